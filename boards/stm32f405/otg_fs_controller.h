// The STM32F405 USB OTG FS device controller behind the device-controller
// seam (firmware/usb/device_controller.h; its contract binds this driver):
// core reset, forced device mode, VBUS sensing as the board wires it, the
// FIFO layout in the 1.25 KiB FIFO RAM, EP0 control transfers one packet at
// a time (SETUP via the RX FIFO and STUP, STALL), SET_ADDRESS (DCFG.DAD at
// once), endpoints 1..3 (bulk and interrupt), and the interrupt handling
// (USBRST, ENUMDNE, RXFLVL, OEPINT, IEPINT with TXFE, USBSUSP, WKUPINT) as
// poll(), which turns it into the seam's events.
//
// Register access: OtgFsController<Access>, Access as in otg_fs_registers.h
// (OtgFsMmio on the MCU: inline volatile accesses, the FIFO word loops are
// plain loads and stores; a fake register block in tests). The code is a
// template for that reason only; otg_fs_controller.cc instantiates it for
// OtgFsMmio, so the board's objects do not compile it again.
//
// Context (the seam's "one context"): init(), poll() and every seam call
// run in one context, the one that runs UsbDevice::service(); poll()
// delivers the events synchronously. The board calls poll() from its main
// loop, or from the OTG_FS interrupt if the stack's service() runs there
// too. No heap, no exceptions; every wait on the core is bounded
// (kPollLimit register reads) and a wait that runs out is counted in
// wait_timeouts().
#ifndef HADYNET_BOARDS_STM32F405_OTG_FS_CONTROLLER_H_
#define HADYNET_BOARDS_STM32F405_OTG_FS_CONTROLLER_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "boards/stm32f405/otg_fs_registers.h"
#include "firmware/usb/device_controller.h"
#include "firmware/usb/usb_spec.h"

namespace hadynet::board::stm32 {

// ---- FIFO layout in the shared FIFO RAM (320 words), in 32-bit words.
// The composite device (firmware/usb/composite_descriptors.h): EP1 IN CDC
// notification (interrupt, 16-byte packets), EP2 OUT/IN CDC data (bulk, 64),
// EP3 IN HID telemetry (interrupt, 64-byte reports).
//  * RX (shared by every OUT endpoint and SETUP): RM0090's sizing rule,
//    (4 x 1 control endpoint + 6) for SETUPs + (64 / 4 + 1) for a max packet
//    and its status + 2 x 2 OUT endpoints (EP0, EP2) + 1 (global OUT NAK),
//    is 32 words; 49 with room for a second, back-to-back packet. 160 holds
//    ~8 packets queued while the main loop is busy before poll() runs (the
//    core NAKs when the FIFO is full: slower, never wrong).
//  * EP0 TX 16: one 64-byte packet (the stack sends EP0 a packet at a time;
//    16 words is also the hardware minimum of a TX FIFO).
//  * EP1 TX 16: the hardware minimum; a SERIAL_STATE notification is 10 bytes.
//  * EP2 TX 64: four 64-byte bulk packets, so a link reply (up to 513 bytes)
//    needs a refill only every 4 packets.
//  * EP3 TX 32: two 64-byte HID reports (one per 0.2 s period is sent).
inline constexpr std::uint32_t kRxFifoWords = 160;
inline constexpr std::array<std::uint32_t, otg::kEndpoints> kTxFifoWords = {16, 16, 64, 32};

// Start address of TX FIFO n (words from the start of the FIFO RAM): the RX
// FIFO first, then the TX FIFOs in endpoint order.
constexpr std::uint32_t tx_fifo_start(int n) noexcept {
  std::uint32_t start = kRxFifoWords;
  for (int k = 0; k < n; ++k) start += kTxFifoWords[static_cast<std::size_t>(k)];
  return start;
}
inline constexpr std::uint32_t kFifoWordsUsed = tx_fifo_start(otg::kEndpoints);
static_assert(kFifoWordsUsed <= otg::kFifoRamWords, "FIFOs exceed the 1.25 KiB OTG FS FIFO RAM");
static_assert(kRxFifoWords >= (4 * 1 + 6) + 2 * (64 / 4 + 1) + 2 * 2 + 1, "RX FIFO below two 64-byte packets");
static_assert(kTxFifoWords[0] * 4 >= usb::kEp0MaxPacket, "EP0 TX FIFO must hold a max packet");
static_assert(
    [] {
      for (const std::uint32_t w : kTxFifoWords) {
        if (w < otg::kMinTxFifoWords) return false;
      }
      return true;
    }(),
    "a TX FIFO is below the hardware minimum of 16 words");

// GUSBCFG.TRDT for an AHB clock (RM0090's table for the full-speed PHY):
// the USB turnaround time in PHY clocks. 0 below 14.2 MHz (USB needs more).
constexpr std::uint32_t turnaround_time(std::uint32_t ahb_hz) noexcept {
  constexpr std::uint32_t kMinHz[] = {32'000'000, 27'700'000, 24'000'000, 21'800'000, 20'000'000,
                                      18'500'000, 17'200'000, 16'000'000, 15'000'000, 14'200'000};
  for (std::uint32_t i = 0; i < sizeof(kMinHz) / sizeof(kMinHz[0]); ++i) {
    if (ahb_hz >= kMinHz[i]) return 6 + i;
  }
  return 0;
}

// Board data of the OTG FS port.
struct OtgFsOptions {
  // true: the board wires VBUS to PA9 and the core senses it (GCCFG.VBUSBSEN;
  // the pull-up follows VBUS). false: VBUS is assumed present
  // (GCCFG.NOVBUSSENS), right for a bus-powered device and for a board
  // whose PA9 is not VBUS. Today's stm32f405 board drives USART1 TX on PA9
  // (board.cc): sensing must stay off there unless the UART moves.
  bool vbus_sensing = false;
  std::uint32_t ahb_clock_hz = 168'000'000;  // HCLK: sets GUSBCFG.TRDT
};

// What the driver needs from the board at init(), outside the peripheral.
class OtgFsBoardHooks {
 public:
  // RCC AHB2ENR.OTGFSEN, GPIOA clock, PA11 (DM) and PA12 (DP) to AF10.
  virtual void enable_clocks_and_pins() noexcept = 0;
  // Returns after at least `ms` milliseconds (forced device mode: 25 ms).
  virtual void wait_ms(std::uint32_t ms) noexcept = 0;

 protected:
  ~OtgFsBoardHooks() = default;
};

// The MCU's hooks (otg_fs_controller.cc): RCC and GPIOA registers, and a
// wait on board::ticks() (SysTick must run: call after board::init()).
class Stm32f405OtgFsHooks final : public OtgFsBoardHooks {
 public:
  void enable_clocks_and_pins() noexcept override;
  void wait_ms(std::uint32_t ms) noexcept override;
};

template <class Access>
class OtgFsController final : public usb::DeviceController {
 public:
  // Register reads a bounded wait makes before giving up (>= 3 ms at 168 MHz;
  // the core's resets and flushes take microseconds).
  static constexpr std::uint32_t kPollLimit = 100'000;
  // poll() handles at most this many rounds of GINTSTS, and this many RX
  // FIFO entries per round, then returns (the rest waits for the next call).
  static constexpr int kMaxRounds = 4;
  static constexpr int kMaxRxEntriesPerRound = 16;

  OtgFsController(Access& access, OtgFsBoardHooks& hooks, const OtgFsOptions& options) noexcept
      : io_(access), hooks_(hooks), options_(options) {}

  // ---- the seam
  void init(usb::ControllerEventHandler& handler) noexcept override;
  void set_connected(bool connected) noexcept override;
  void set_address(std::uint8_t address) noexcept override;
  bool open_endpoint(const usb::EndpointConfig& config) noexcept override;
  void close_endpoint(usb::EndpointAddress ep) noexcept override;
  bool start_transfer(usb::EndpointAddress ep, std::span<std::uint8_t> buffer) noexcept override;
  void stall_control() noexcept override;
  void set_endpoint_halt(usb::EndpointAddress ep, bool halted) noexcept override;

  // Handles the core's pending interrupts and delivers the seam's events.
  // Safe to call before init() (does nothing) and when nothing is pending.
  void poll() noexcept;

  // Bounded waits that ran out (core reset, FIFO flush, endpoint disable).
  std::uint32_t wait_timeouts() const noexcept { return wait_timeouts_; }
  // OUT bytes the host sent beyond the armed buffer (discarded).
  std::uint32_t dropped_out_bytes() const noexcept { return dropped_out_bytes_; }

 private:
  struct Endpoint {
    bool open = false;
    bool halted = false;
    bool active = false;           // a transfer is in progress
    std::uint16_t max_packet = 0;  // bytes
    std::uint8_t* data = nullptr;  // the stack's buffer
    std::uint16_t size = 0;        // IN: bytes to send; OUT: buffer capacity
    std::uint16_t done = 0;        // IN: bytes pushed into the TX FIFO; OUT: bytes received
  };

  static constexpr std::size_t index(usb::EndpointAddress ep) noexcept {
    return static_cast<std::size_t>(usb::endpoint_number(ep)) * 2 + (usb::is_in(ep) ? 1 : 0);
  }
  static constexpr bool valid(usb::EndpointAddress ep) noexcept {
    return usb::endpoint_number(ep) <= usb::kMaxEndpointNumber && (ep & 0x70) == 0;
  }
  Endpoint& in(int n) noexcept { return endpoints_[static_cast<std::size_t>(n) * 2 + 1]; }
  Endpoint& out(int n) noexcept { return endpoints_[static_cast<std::size_t>(n) * 2]; }

  std::uint32_t read(std::uint32_t offset) const noexcept { return io_.read(offset); }
  void write(std::uint32_t offset, std::uint32_t value) noexcept { io_.write(offset, value); }
  void set_bits(std::uint32_t offset, std::uint32_t bits) noexcept { write(offset, read(offset) | bits); }
  void clear_bits(std::uint32_t offset, std::uint32_t bits) noexcept { write(offset, read(offset) & ~bits); }
  // Read-modify-write of DIEPCTLn/DOEPCTLn that never re-writes the action
  // bits (EPENA, EPDIS, SNAK, CNAK, SD0PID) it read back.
  void modify_endpoint_control(std::uint32_t offset, std::uint32_t clear, std::uint32_t set) noexcept;
  bool wait_for(std::uint32_t offset, std::uint32_t mask, std::uint32_t value) noexcept;

  void core_reset() noexcept;
  void program_fifos() noexcept;
  void flush_tx_fifo(std::uint32_t fifo_number) noexcept;  // 0..3, or otg::kGrstctlTxFlushAll
  void flush_rx_fifo() noexcept;
  void arm_setup() noexcept;  // EP0 OUT accepts up to 3 back-to-back SETUPs
  void disable_in(int n) noexcept;
  void disable_out(int n) noexcept;
  void drop_transfer(usb::EndpointAddress ep) noexcept;

  void bus_reset() noexcept;
  void enumeration_done() noexcept;
  void drain_rx_fifo() noexcept;
  void out_endpoint_interrupts() noexcept;
  void in_endpoint_interrupts() noexcept;
  void setup_done() noexcept;
  void fill_tx_fifo(int n) noexcept;
  void read_packet(std::uint8_t* dest, std::size_t keep, std::size_t bytes) noexcept;
  void deliver(const usb::ControllerEvent& event) noexcept { handler_->handle(event); }

  Access& io_;
  OtgFsBoardHooks& hooks_;
  OtgFsOptions options_;
  usb::ControllerEventHandler* handler_ = nullptr;
  std::array<Endpoint, 2 * otg::kEndpoints> endpoints_{};
  std::array<std::uint8_t, usb::kSetupPacketSize> setup_{};
  bool setup_valid_ = false;
  std::uint32_t wait_timeouts_ = 0;
  std::uint32_t dropped_out_bytes_ = 0;
};

// ============================================================================
// Definitions of OtgFsController (a template: see the top of this file).
// ============================================================================

template <class Access>
void OtgFsController<Access>::modify_endpoint_control(std::uint32_t offset, std::uint32_t clear,
                                                      std::uint32_t set) noexcept {
  constexpr std::uint32_t kActions =
      otg::kEpctlEnable | otg::kEpctlDisable | otg::kEpctlSetNak | otg::kEpctlClearNak | otg::kEpctlSetData0;
  write(offset, (read(offset) & ~(kActions | clear)) | set);
}

template <class Access>
bool OtgFsController<Access>::wait_for(std::uint32_t offset, std::uint32_t mask, std::uint32_t value) noexcept {
  for (std::uint32_t i = 0; i < kPollLimit; ++i) {
    if ((read(offset) & mask) == value) return true;
  }
  ++wait_timeouts_;
  return false;
}

// ---- init ---------------------------------------------------------------------

template <class Access>
void OtgFsController<Access>::core_reset() noexcept {
  // RM0090 core initialisation: the AHB master idle, then the soft reset,
  // which the core clears when done.
  wait_for(otg::kGrstctl, otg::kGrstctlAhbIdle, otg::kGrstctlAhbIdle);
  write(otg::kGrstctl, otg::kGrstctlCoreReset);
  wait_for(otg::kGrstctl, otg::kGrstctlCoreReset, 0);
  wait_for(otg::kGrstctl, otg::kGrstctlAhbIdle, otg::kGrstctlAhbIdle);
}

template <class Access>
void OtgFsController<Access>::program_fifos() noexcept {
  write(otg::kGrxfsiz, kRxFifoWords);
  write(otg::kDieptxf0, (kTxFifoWords[0] << otg::kTxFifoDepth) | tx_fifo_start(0));
  for (int n = 1; n < otg::kEndpoints; ++n) {
    write(otg::dieptxf(n), (kTxFifoWords[static_cast<std::size_t>(n)] << otg::kTxFifoDepth) | tx_fifo_start(n));
  }
}

template <class Access>
void OtgFsController<Access>::flush_tx_fifo(std::uint32_t fifo_number) noexcept {
  write(otg::kGrstctl, otg::kGrstctlTxFlush | (fifo_number << otg::kGrstctlTxFifoNumber));
  wait_for(otg::kGrstctl, otg::kGrstctlTxFlush, 0);
}

template <class Access>
void OtgFsController<Access>::flush_rx_fifo() noexcept {
  write(otg::kGrstctl, otg::kGrstctlRxFlush);
  wait_for(otg::kGrstctl, otg::kGrstctlRxFlush, 0);
}

template <class Access>
void OtgFsController<Access>::arm_setup() noexcept {
  write(otg::doeptsiz(0), 3u << otg::kTsizSetupCount);
}

template <class Access>
void OtgFsController<Access>::init(usb::ControllerEventHandler& handler) noexcept {
  handler_ = &handler;
  endpoints_ = {};
  setup_valid_ = false;
  hooks_.enable_clocks_and_pins();

  // Core: embedded full-speed PHY, soft reset, then the PHY powered and
  // VBUS sensing as the board wires it.
  set_bits(otg::kGusbcfg, otg::kGusbcfgPhySelect);
  core_reset();
  write(otg::kGccfg,
        otg::kGccfgPhyPowerUp | (options_.vbus_sensing ? otg::kGccfgVbusSenseB : otg::kGccfgNoVbusSensing));
  // Device mode forced (the ID pin is not used), turnaround time for HCLK.
  // The mode change takes effect after 25 ms.
  write(otg::kGusbcfg, (read(otg::kGusbcfg) & ~(otg::kGusbcfgForceHost | otg::kGusbcfgTurnaroundMask)) |
                           otg::kGusbcfgForceDevice | otg::kGusbcfgPhySelect |
                           (turnaround_time(options_.ahb_clock_hz) << otg::kGusbcfgTurnaround));
  hooks_.wait_ms(25);
  write(otg::kPcgcctl, 0);  // PHY clock not stopped or gated

  // Device: full speed, address 0, pull-up off until set_connected(true).
  write(otg::kDcfg, (read(otg::kDcfg) & ~(otg::kDcfgSpeedMask | otg::kDcfgAddressMask)) | otg::kDcfgSpeedFull);
  set_bits(otg::kDctl, otg::kDctlSoftDisconnect);

  program_fifos();
  flush_tx_fifo(otg::kGrstctlTxFlushAll);
  flush_rx_fifo();

  // Every endpoint off, its interrupts cleared; EP0 ready for SETUPs.
  write(otg::kDiepmsk, 0);
  write(otg::kDoepmsk, 0);
  write(otg::kDaintmsk, 0);
  write(otg::kDiepempmsk, 0);
  for (int n = 0; n < otg::kEndpoints; ++n) {
    disable_in(n);
    disable_out(n);
    write(otg::diepctl(n), otg::kEpctlSetNak);
    write(otg::doepctl(n), otg::kEpctlSetNak);
    write(otg::diepint(n), 0xFF);
    write(otg::doepint(n), 0xFF);
  }
  write(otg::kDiepmsk, otg::kInTransferComplete);
  write(otg::kDoepmsk, otg::kOutTransferComplete | otg::kOutSetupDone);
  write(otg::kDaintmsk, otg::daint_in(0) | otg::daint_out(0));
  in(0).open = out(0).open = true;
  in(0).max_packet = out(0).max_packet = usb::kEp0MaxPacket;
  arm_setup();

  // Core interrupts: the ones poll() handles. TXFE only when a TX FIFO is
  // completely empty (a packet is pushed whole).
  write(otg::kGintsts, 0xFFFFFFFF);
  write(otg::kGintmsk, otg::kGintBusReset | otg::kGintEnumerationDone | otg::kGintRxFifoNonEmpty |
                           otg::kGintInEndpoint | otg::kGintOutEndpoint | otg::kGintSuspend | otg::kGintWakeup);
  write(otg::kGahbcfg, otg::kGahbcfgGlobalInterrupt | otg::kGahbcfgTxEmptyLevel);
}

template <class Access>
void OtgFsController<Access>::set_connected(bool connected) noexcept {
  if (connected) {
    clear_bits(otg::kDctl, otg::kDctlSoftDisconnect);
  } else {
    set_bits(otg::kDctl, otg::kDctlSoftDisconnect);
  }
}

template <class Access>
void OtgFsController<Access>::set_address(std::uint8_t address) noexcept {
  // At once: the core answers the status stage on the old address itself.
  write(otg::kDcfg, (read(otg::kDcfg) & ~otg::kDcfgAddressMask) |
                        ((static_cast<std::uint32_t>(address) << otg::kDcfgAddress) & otg::kDcfgAddressMask));
}

// ---- endpoints ------------------------------------------------------------------

template <class Access>
void OtgFsController<Access>::disable_in(int n) noexcept {
  // An enabled IN endpoint: NAK, disable, wait for EPDISD, empty its FIFO.
  if ((read(otg::diepctl(n)) & otg::kEpctlEnable) == 0) return;
  modify_endpoint_control(otg::diepctl(n), 0, otg::kEpctlSetNak | otg::kEpctlDisable);
  wait_for(otg::diepint(n), otg::kInDisabled, otg::kInDisabled);
  write(otg::diepint(n), otg::kInDisabled);
  flush_tx_fifo(static_cast<std::uint32_t>(n));
}

template <class Access>
void OtgFsController<Access>::disable_out(int n) noexcept {
  // An enabled OUT endpoint is disabled under global OUT NAK (RM0090).
  if (n == 0 || (read(otg::doepctl(n)) & otg::kEpctlEnable) == 0) return;
  set_bits(otg::kDctl, otg::kDctlSetGlobalOutNak);
  wait_for(otg::kGintsts, otg::kGintGlobalOutNakEffective, otg::kGintGlobalOutNakEffective);
  modify_endpoint_control(otg::doepctl(n), 0, otg::kEpctlSetNak | otg::kEpctlDisable);
  wait_for(otg::doepint(n), otg::kOutDisabled, otg::kOutDisabled);
  write(otg::doepint(n), otg::kOutDisabled);
  set_bits(otg::kDctl, otg::kDctlClearGlobalOutNak);
}

template <class Access>
void OtgFsController<Access>::drop_transfer(usb::EndpointAddress ep) noexcept {
  const int n = usb::endpoint_number(ep);
  if (usb::is_in(ep)) {
    disable_in(n);
    clear_bits(otg::kDiepempmsk, 1u << n);
  } else {
    disable_out(n);
  }
  Endpoint& e = endpoints_[index(ep)];
  e.active = false;
  e.data = nullptr;
  e.size = e.done = 0;
}

template <class Access>
bool OtgFsController<Access>::open_endpoint(const usb::EndpointConfig& config) noexcept {
  const usb::EndpointAddress ep = config.address;
  const int n = usb::endpoint_number(ep);
  if (!valid(ep) || n == 0) return false;
  if (config.type != usb::EndpointType::kBulk && config.type != usb::EndpointType::kInterrupt) return false;
  if (config.max_packet == 0 || config.max_packet > 64) return false;
  const bool is_in = usb::is_in(ep);
  if (is_in && config.max_packet > 4 * kTxFifoWords[static_cast<std::size_t>(n)]) return false;
  if (endpoints_[index(ep)].open) close_endpoint(ep);

  const std::uint32_t control = otg::kEpctlActive | otg::kEpctlSetData0 | otg::kEpctlSetNak |
                                (static_cast<std::uint32_t>(config.type) << otg::kEpctlType) | config.max_packet;
  if (is_in) {
    write(otg::diepctl(n), control | (static_cast<std::uint32_t>(n) << otg::kEpctlTxFifo));
    set_bits(otg::kDaintmsk, otg::daint_in(n));
  } else {
    write(otg::doepctl(n), control);
    set_bits(otg::kDaintmsk, otg::daint_out(n));
  }
  Endpoint& e = endpoints_[index(ep)];
  e = Endpoint{};
  e.open = true;
  e.max_packet = config.max_packet;
  return true;
}

template <class Access>
void OtgFsController<Access>::close_endpoint(usb::EndpointAddress ep) noexcept {
  const int n = usb::endpoint_number(ep);
  if (!valid(ep) || n == 0) return;
  drop_transfer(ep);
  if (usb::is_in(ep)) {
    write(otg::diepctl(n), otg::kEpctlSetNak);  // USBAEP, STALL, type cleared
    clear_bits(otg::kDaintmsk, otg::daint_in(n));
  } else {
    write(otg::doepctl(n), otg::kEpctlSetNak);
    clear_bits(otg::kDaintmsk, otg::daint_out(n));
  }
  endpoints_[index(ep)] = Endpoint{};
}

template <class Access>
bool OtgFsController<Access>::start_transfer(usb::EndpointAddress ep, std::span<std::uint8_t> buffer) noexcept {
  if (!valid(ep)) return false;
  const int n = usb::endpoint_number(ep);
  Endpoint& e = endpoints_[index(ep)];
  if (!e.open || e.halted || e.active) return false;
  const std::size_t size = buffer.size();
  if (n == 0 ? size > usb::kEp0MaxPacket : size > 0xFFFF) return false;  // events carry 16-bit counts
  const std::uint32_t mps = e.max_packet;

  if (usb::is_in(ep)) {
    // One packet per max packet, the last short; 0 bytes: one ZLP.
    const std::uint32_t packets = size == 0 ? 1 : static_cast<std::uint32_t>((size + mps - 1) / mps);
    if (packets > otg::kTsizPacketCountMax) return false;
    e.active = true;
    e.data = buffer.data();
    e.size = static_cast<std::uint16_t>(size);
    e.done = 0;
    write(otg::dieptsiz(n), (packets << otg::kTsizPacketCount) | static_cast<std::uint32_t>(size));
    modify_endpoint_control(otg::diepctl(n), 0, otg::kEpctlEnable | otg::kEpctlClearNak);
    if (size > 0) set_bits(otg::kDiepempmsk, 1u << n);  // TXFE: poll() pushes the packets
    return true;
  }

  // OUT: EP0 one packet of up to 64 bytes (and SETUPs stay accepted);
  // EP1..3 whole max packets.
  std::uint32_t tsiz = 0;
  if (n == 0) {
    tsiz =
        (3u << otg::kTsizSetupCount) | (1u << otg::kTsizPacketCount) | static_cast<std::uint32_t>(usb::kEp0MaxPacket);
  } else {
    if (size % mps != 0) return false;
    const std::uint32_t packets = size == 0 ? 1 : static_cast<std::uint32_t>(size / mps);
    if (packets > otg::kTsizPacketCountMax) return false;
    tsiz = (packets << otg::kTsizPacketCount) | (packets * mps);
  }
  e.active = true;
  e.data = buffer.data();
  e.size = static_cast<std::uint16_t>(size);
  e.done = 0;
  write(otg::doeptsiz(n), tsiz);
  modify_endpoint_control(otg::doepctl(n), 0, otg::kEpctlEnable | otg::kEpctlClearNak);
  return true;
}

template <class Access>
void OtgFsController<Access>::stall_control() noexcept {
  // Both EP0 directions STALL until the next SETUP (the core clears the EP0
  // STALL bits itself when a SETUP arrives).
  drop_transfer(usb::in_endpoint(0));
  out(0).active = false;
  modify_endpoint_control(otg::diepctl(0), 0, otg::kEpctlStall);
  modify_endpoint_control(otg::doepctl(0), 0, otg::kEpctlStall);
  arm_setup();
}

template <class Access>
void OtgFsController<Access>::set_endpoint_halt(usb::EndpointAddress ep, bool halted) noexcept {
  const int n = usb::endpoint_number(ep);
  if (!valid(ep) || n == 0 || !endpoints_[index(ep)].open) return;
  drop_transfer(ep);  // the seam: an active transfer is dropped either way
  endpoints_[index(ep)].halted = halted;
  const std::uint32_t control = usb::is_in(ep) ? otg::diepctl(n) : otg::doepctl(n);
  if (halted) {
    modify_endpoint_control(control, 0, otg::kEpctlStall);
  } else {
    modify_endpoint_control(control, otg::kEpctlStall, otg::kEpctlSetData0 | otg::kEpctlSetNak);
  }
}

// ---- interrupts -----------------------------------------------------------------

template <class Access>
void OtgFsController<Access>::poll() noexcept {
  if (handler_ == nullptr) return;
  for (int round = 0; round < kMaxRounds; ++round) {
    const std::uint32_t pending = read(otg::kGintsts) & read(otg::kGintmsk);
    if (pending == 0) return;
    if ((pending & otg::kGintBusReset) != 0) {
      write(otg::kGintsts, otg::kGintBusReset);
      bus_reset();
      continue;  // whatever else was pending belonged to the old session
    }
    if ((pending & otg::kGintEnumerationDone) != 0) {
      write(otg::kGintsts, otg::kGintEnumerationDone);
      enumeration_done();
    }
    // RX first: popping a SETUP's "stage done" entry is what raises STUP,
    // so the endpoint flags are read after it.
    if ((pending & otg::kGintRxFifoNonEmpty) != 0) drain_rx_fifo();
    const std::uint32_t endpoints = read(otg::kGintsts) & read(otg::kGintmsk);
    if ((endpoints & otg::kGintOutEndpoint) != 0) out_endpoint_interrupts();
    if ((endpoints & otg::kGintInEndpoint) != 0) in_endpoint_interrupts();
    if ((pending & otg::kGintSuspend) != 0) {
      write(otg::kGintsts, otg::kGintSuspend);
      deliver(usb::ControllerEvent::suspend());
    }
    if ((pending & otg::kGintWakeup) != 0) {
      write(otg::kGintsts, otg::kGintWakeup);
      deliver(usb::ControllerEvent::resume());
    }
  }
}

template <class Access>
void OtgFsController<Access>::bus_reset() noexcept {
  // RM0090 "endpoint initialisation on USB reset", and the seam: every
  // transfer aborted, endpoints 1..3 closed, address 0, EP0 ready.
  for (int n = 0; n < otg::kEndpoints; ++n) {
    if ((read(otg::diepctl(n)) & otg::kEpctlEnable) != 0) {
      modify_endpoint_control(otg::diepctl(n), 0, otg::kEpctlSetNak | otg::kEpctlDisable);
    }
    if (n != 0 && (read(otg::doepctl(n)) & otg::kEpctlEnable) != 0) {
      modify_endpoint_control(otg::doepctl(n), 0, otg::kEpctlSetNak | otg::kEpctlDisable);
    }
    write(otg::diepctl(n), otg::kEpctlSetNak);  // EP0: STALL off; EP1..3: USBAEP off
    write(otg::doepctl(n), otg::kEpctlSetNak);
    write(otg::diepint(n), 0xFF);
    write(otg::doepint(n), 0xFF);
  }
  flush_tx_fifo(otg::kGrstctlTxFlushAll);
  flush_rx_fifo();
  write(otg::kDcfg, read(otg::kDcfg) & ~otg::kDcfgAddressMask);
  write(otg::kDiepempmsk, 0);
  write(otg::kDaintmsk, otg::daint_in(0) | otg::daint_out(0));
  write(otg::kDiepmsk, otg::kInTransferComplete);
  write(otg::kDoepmsk, otg::kOutTransferComplete | otg::kOutSetupDone);
  program_fifos();
  arm_setup();

  endpoints_ = {};
  in(0).open = out(0).open = true;
  in(0).max_packet = out(0).max_packet = usb::kEp0MaxPacket;
  setup_valid_ = false;
  deliver(usb::ControllerEvent::bus_reset());
}

template <class Access>
void OtgFsController<Access>::enumeration_done() noexcept {
  // Full speed is the only speed; EP0 max packet 64, IN NAK released.
  modify_endpoint_control(otg::diepctl(0), otg::kEpctl0MaxPacketMask, otg::kEpctl0MaxPacket64);
  set_bits(otg::kDctl, otg::kDctlClearGlobalInNak);
}

template <class Access>
void OtgFsController<Access>::read_packet(std::uint8_t* dest, std::size_t keep, std::size_t bytes) noexcept {
  // Pops ceil(bytes / 4) words; the first `keep` bytes go to `dest`.
  const std::size_t words = (bytes + 3) / 4;
  for (std::size_t w = 0; w < words; ++w) {
    const std::uint32_t word = io_.read_fifo_word();
    for (std::size_t k = 0; k < 4; ++k) {
      const std::size_t i = 4 * w + k;
      if (i < keep) dest[i] = static_cast<std::uint8_t>(word >> (8 * k));
    }
  }
}

template <class Access>
void OtgFsController<Access>::drain_rx_fifo() noexcept {
  for (int entry = 0; entry < kMaxRxEntriesPerRound; ++entry) {
    if ((read(otg::kGintsts) & otg::kGintRxFifoNonEmpty) == 0) return;
    const std::uint32_t status = read(otg::kGrxstsp);
    const int n = static_cast<int>(status & otg::kRxStatusEndpointMask) & usb::kMaxEndpointNumber;
    const std::size_t bytes = (status & otg::kRxStatusByteCountMask) >> otg::kRxStatusByteCount;
    switch ((status & otg::kRxStatusPacketStatusMask) >> otg::kRxStatusPacketStatus) {
      case otg::kRxSetupData:
        // Back-to-back SETUPs: the last one counts.
        read_packet(setup_.data(), bytes == usb::kSetupPacketSize ? bytes : 0, bytes);
        setup_valid_ = bytes == usb::kSetupPacketSize;
        break;
      case otg::kRxOutData: {
        Endpoint& e = out(n);
        std::size_t keep = 0;
        if (e.active) {
          const std::size_t room = static_cast<std::size_t>(e.size - e.done);
          keep = bytes < room ? bytes : room;
        }
        read_packet(e.active ? e.data + e.done : nullptr, keep, bytes);
        e.done = static_cast<std::uint16_t>(e.done + keep);
        dropped_out_bytes_ += static_cast<std::uint32_t>(bytes - keep);
        break;
      }
      default:  // OUT complete, SETUP stage done, global OUT NAK: no data
        break;
    }
  }
}

template <class Access>
void OtgFsController<Access>::setup_done() noexcept {
  // A SETUP cancels both EP0 transfers silently and clears the EP0 stall.
  drop_transfer(usb::in_endpoint(0));
  out(0).active = false;
  modify_endpoint_control(otg::diepctl(0), otg::kEpctlStall, 0);
  modify_endpoint_control(otg::doepctl(0), otg::kEpctlStall, 0);
  arm_setup();
  if (!setup_valid_) return;
  setup_valid_ = false;
  deliver(usb::ControllerEvent::setup_packet(setup_));
}

template <class Access>
void OtgFsController<Access>::out_endpoint_interrupts() noexcept {
  const std::uint32_t daint = read(otg::kDaint) & read(otg::kDaintmsk);
  for (int n = 0; n < otg::kEndpoints; ++n) {
    if ((daint & otg::daint_out(n)) == 0) continue;
    const std::uint32_t flags = read(otg::doepint(n)) & read(otg::kDoepmsk);
    write(otg::doepint(n), flags);
    if ((flags & otg::kOutTransferComplete) != 0 && out(n).active) {
      Endpoint& e = out(n);
      e.active = false;
      deliver(usb::ControllerEvent::transfer_complete(usb::out_endpoint(static_cast<std::uint8_t>(n)), e.done));
    }
    if (n == 0 && (flags & otg::kOutSetupDone) != 0) setup_done();
  }
}

template <class Access>
void OtgFsController<Access>::fill_tx_fifo(int n) noexcept {
  // Whole packets while the FIFO has room; TXFE comes again when it empties.
  Endpoint& e = in(n);
  while (e.active && e.done < e.size) {
    const std::size_t left = static_cast<std::size_t>(e.size - e.done);
    const std::size_t bytes = left < e.max_packet ? left : e.max_packet;
    const std::uint32_t words = static_cast<std::uint32_t>((bytes + 3) / 4);
    if ((read(otg::dtxfsts(n)) & otg::kDtxfstsSpaceMask) < words) return;
    const std::uint8_t* p = e.data + e.done;
    for (std::size_t i = 0; i < bytes; i += 4) {
      std::uint32_t word = 0;
      for (std::size_t k = 0; k < 4 && i + k < bytes; ++k) word |= static_cast<std::uint32_t>(p[i + k]) << (8 * k);
      io_.write_fifo_word(n, word);  // the last word padded with zeros
    }
    e.done = static_cast<std::uint16_t>(e.done + bytes);
  }
  clear_bits(otg::kDiepempmsk, 1u << n);  // all pushed (or no transfer)
}

template <class Access>
void OtgFsController<Access>::in_endpoint_interrupts() noexcept {
  const std::uint32_t daint = read(otg::kDaint) & read(otg::kDaintmsk);
  for (int n = 0; n < otg::kEndpoints; ++n) {
    if ((daint & otg::daint_in(n)) == 0) continue;
    const std::uint32_t flags = read(otg::diepint(n)) & read(otg::kDiepmsk);
    write(otg::diepint(n), flags);
    if ((flags & otg::kInTransferComplete) != 0 && in(n).active) {
      Endpoint& e = in(n);
      e.active = false;
      clear_bits(otg::kDiepempmsk, 1u << n);
      deliver(usb::ControllerEvent::transfer_complete(usb::in_endpoint(static_cast<std::uint8_t>(n)), e.size));
    }
    // TXFE (read only, a level): only while this endpoint waits to push.
    if ((read(otg::kDiepempmsk) & (1u << n)) != 0 && (read(otg::diepint(n)) & otg::kInTxFifoEmpty) != 0) {
      fill_tx_fifo(n);
    }
  }
}

extern template class OtgFsController<otg::OtgFsMmio>;
using Stm32f405OtgFs = OtgFsController<otg::OtgFsMmio>;

}  // namespace hadynet::board::stm32

#endif  // HADYNET_BOARDS_STM32F405_OTG_FS_CONTROLLER_H_
