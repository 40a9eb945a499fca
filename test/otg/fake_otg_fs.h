// A fake OTG FS core for the driver's tests: the register block in RAM,
// reached through the same four operations as otg::OtgFsMmio (read, write,
// write_fifo_word, read_fifo_word), plus the core's side effects the driver
// relies on, modelled after RM0090:
//   * GINTSTS: latched events (USBRST, ENUMDNE, USBSUSP, WKUPINT) are
//     write-1-to-clear; RXFLVL, IEPINT, OEPINT and GONAKEFF are computed
//     from the RX queue, DAINT and DCTL.
//   * GRSTCTL: CSRST, RXFFLSH and TXFFLSH clear at once (counted), AHBIDL is
//     set; a TX flush empties the named FIFO(s).
//   * GRXSTSP pops the receive-status queue; popping "SETUP stage done" sets
//     DOEPINT0.STUP, popping "OUT transfer complete" sets DOEPINTn.XFRC.
//   * DIEPINTn/DOEPINTn: write-1-to-clear; DIEPINTn.TXFE while TX FIFO n is
//     empty; DAINT from them and DIEPMSK/DOEPMSK/DIEPEMPMSK.
//   * DIEPCTLn/DOEPCTLn: SNAK/CNAK/SD0PID are actions (not stored; SD0PID
//     is recorded), EPDIS on an enabled endpoint clears EPENA and sets
//     EPDISD, writing EPENA = 0 does not disable.
//   * DTXFSTSn: the TX FIFO depth (from DIEPTXF0/DIEPTXFn) minus the words
//     queued in it.
// The host side: bus events, SETUP and OUT packets into the RX queue, and IN
// tokens that take one packet out of a TX FIFO (decrementing DIEPTSIZn and
// raising XFRC when the packet count reaches 0).
#ifndef HADYNET_TEST_OTG_FAKE_OTG_FS_H_
#define HADYNET_TEST_OTG_FAKE_OTG_FS_H_

#include <array>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <vector>

#include "boards/stm32f405/otg_fs_controller.h"

namespace hadynet::board::stm32::testing {

class FakeOtgFs {
 public:
  static constexpr std::size_t kRegisterWords = 0x1000 / 4;  // offsets below the FIFO windows

  FakeOtgFs();

  // ---- the access policy (the driver calls these)
  std::uint32_t read(std::uint32_t offset);
  void write(std::uint32_t offset, std::uint32_t value);
  void write_fifo_word(int fifo, std::uint32_t word);
  std::uint32_t read_fifo_word();

  // ---- the host and the bus
  void bus_reset() { latched_ |= otg::kGintBusReset; }
  void enumeration_done() { latched_ |= otg::kGintEnumerationDone; }
  void suspend() { latched_ |= otg::kGintSuspend; }
  void wakeup() { latched_ |= otg::kGintWakeup; }
  // A SETUP packet on EP0: "SETUP data" (8 bytes) and "SETUP stage done".
  void setup(std::span<const std::uint8_t, 8> packet);
  // An OUT packet on endpoint n; false (NAK) unless the endpoint is enabled.
  bool out_packet(int n, std::span<const std::uint8_t> packet);
  // An IN token on endpoint n: the next packet (max packet or the rest), or
  // nothing (NAK: not enabled, or the packet is not in the FIFO yet).
  std::optional<std::vector<std::uint8_t>> in_token(int n);
  // Raw receive-status entries and data words (scripted RX FIFO).
  void queue_rx(std::uint32_t status, std::span<const std::uint32_t> words = {});
  static std::uint32_t rx_status(int ep, std::uint32_t packet_status, std::uint32_t bytes);

  // ---- observations
  std::uint32_t reg(std::uint32_t offset) const { return regs_[offset / 4]; }
  void set_reg(std::uint32_t offset, std::uint32_t value) { regs_[offset / 4] = value; }
  const std::vector<std::uint32_t>& pushed_words(int fifo) const { return pushed_[static_cast<std::size_t>(fifo)]; }
  std::size_t queued_words(int fifo) const { return tx_[static_cast<std::size_t>(fifo)].size(); }
  std::size_t rx_words_left() const { return rx_data_.size(); }
  std::size_t rx_entries_left() const { return rx_status_.size(); }
  int core_resets() const { return core_resets_; }
  int tx_flushes() const { return tx_flushes_; }
  int rx_flushes() const { return rx_flushes_; }
  int fifo_underruns() const { return fifo_underruns_; }
  int fifo_overruns() const { return fifo_overruns_; }
  bool data0_set(bool in, int n) const { return (in ? in_data0_ : out_data0_)[static_cast<std::size_t>(n)]; }
  void clear_data0_marks() {
    in_data0_ = {};
    out_data0_ = {};
  }
  std::uint32_t tx_fifo_depth(int n) const;

 private:
  std::uint32_t gintsts() const;
  std::uint32_t daint() const;
  std::uint32_t diepint(int n) const;
  void write_endpoint_control(std::uint32_t offset, std::uint32_t value, bool in, int n);
  static int endpoint_of(std::uint32_t offset, std::uint32_t base);

  std::array<std::uint32_t, kRegisterWords> regs_{};
  std::uint32_t latched_ = 0;  // GINTSTS events until written 1
  std::deque<std::uint32_t> rx_status_;
  std::deque<std::uint32_t> rx_data_;
  std::array<std::deque<std::uint32_t>, otg::kEndpoints> tx_;
  std::array<std::vector<std::uint32_t>, otg::kEndpoints> pushed_;
  std::array<bool, otg::kEndpoints> in_data0_{};
  std::array<bool, otg::kEndpoints> out_data0_{};
  bool global_out_nak_ = false;
  int core_resets_ = 0;
  int tx_flushes_ = 0;
  int rx_flushes_ = 0;
  int fifo_underruns_ = 0;
  int fifo_overruns_ = 0;
};

// Hooks that record what the driver asked of the board.
struct RecordingHooks final : OtgFsBoardHooks {
  void enable_clocks_and_pins() noexcept override { ++enables; }
  void wait_ms(std::uint32_t ms) noexcept override { waited_ms += ms; }
  int enables = 0;
  std::uint32_t waited_ms = 0;
};

using FakeDriver = OtgFsController<FakeOtgFs>;

}  // namespace hadynet::board::stm32::testing

#endif  // HADYNET_TEST_OTG_FAKE_OTG_FS_H_
