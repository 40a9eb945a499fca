// The DFU interface of the simulated STM32 ROM bootloader: DFU 1.1 in DFU
// mode with ST's DfuSe extension as AN3156 describes it, over RomFlashModel.
//
//   DNLOAD block 0     a command, run by the next GETSTATUS (dfuDNBUSY with
//                      bwPollTimeout), the GETSTATUS after gives
//                      dfuDNLOAD-IDLE or dfuERROR:
//                        0x21 a32  set the address pointer (outside the
//                                  flash: errTARGET)
//                        0x41 a32  erase the sector holding a (outside: errTARGET)
//                        0x41      mass erase
//                        0x92      read unprotect: not modelled, errUNKNOWN
//   DNLOAD block n>=2  program at pointer + (n-2) * 2048 (same polling);
//                      outside the flash: errADDRESS; a byte that needed a 0
//                      bit to become 1 (not erased): the cells keep the AND
//                      and the ROM's program check reports errVERIFY
//   DNLOAD length 0    in dfuIDLE / dfuDNLOAD-IDLE: "leave"; the next
//                      GETSTATUS answers dfuMANIFEST, and after its status
//                      stage the device jumps to the pointer and drops off
//                      the bus
//   UPLOAD block 0     the command list 0x00 0x21 0x41 0x92
//   UPLOAD block n>=2  read pointer + (n-2) * 2048 (outside: STALL, errADDRESS)
//   GETSTATE, CLRSTATUS (dfuERROR -> dfuIDLE), ABORT (-> dfuIDLE) per DFU 1.1
//   DETACH             not valid in DFU mode (DFU 1.1 table A.2): STALL,
//                      dfuERROR errSTALLEDPKT, like any request not allowed in
//                      the current state; unknown bRequest: STALL only
//
// Only alternate 0 (internal flash) has memory behind it; on alternates 1..3
// (option bytes, OTP, device feature) every command, write and read fails
// with errTARGET / errADDRESS.
// bwPollTimeout: erase = the sector's worst-case erase time
// (stm32f405_flash_layout.h), mass erase = the sum, write = 25 us/byte
// rounded up to ms, set address and leave 1 ms. Nothing sleeps here, but a
// real host sleeps what the device reports: set_poll_timeout_percent()
// scales the reported value (100 = the datasheet figures above, 0 = no wait
// at all, e.g. 1 for tests through a real client that must stay fast).
#ifndef HADYNET_TEST_DFUSE_SIM_DFUSE_ROM_INTERFACE_H_
#define HADYNET_TEST_DFUSE_SIM_DFUSE_ROM_INTERFACE_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "firmware/usb/dfu_spec.h"
#include "firmware/usb/usb_function.h"
#include "test/dfuse_sim/rom_flash_model.h"

namespace hadynet::usb::host_testing {

inline constexpr std::uint16_t kDfuseTransferSize = 2048;  // wTransferSize, bytes
inline constexpr std::uint8_t kDfuseAlternates = 4;

// Fault injection. Block numbers are DNLOAD wValues (>= 2 for data).
struct DfuseFaults {
  // 0 = never. After the GETSTATUS that programs block N (answered
  // dfuDNBUSY, status stage done) the device leaves the bus: attached()
  // false, no further answers.
  std::uint16_t vanish_after_block = 0;
  // 0 = never. Block N is not programmed; the GETSTATUS after its dfuDNBUSY
  // answers dfuERROR with `error_status`.
  std::uint16_t error_at_block = 0;
  dfu::Status error_status = dfu::Status::kErrProg;
  // 0 = none: after any write that covers `leaky_cell_address`, that cell's
  // `leaky_cell_mask` bits read 1 (see RomFlashModel).
  std::uint32_t leaky_cell_address = 0;
  std::uint8_t leaky_cell_mask = 0;
  // The `stall_occurrence`-th request (from 1) with this bRequest STALLs
  // and enters dfuERROR errSTALLEDPKT.
  std::optional<std::uint8_t> stall_request;
  std::uint32_t stall_occurrence = 1;
};

class DfuseRomInterface final : public UsbFunction {
 public:
  DfuseRomInterface(RomFlashModel& flash, const DfuseFaults& faults, std::uint8_t interface) noexcept
      : flash_(flash), faults_(faults), interface_(interface) {}

  bool owns_interface(std::uint8_t interface) const noexcept override { return interface == interface_; }
  bool owns_endpoint(EndpointAddress) const noexcept override { return false; }
  ControlReply control_setup(const SetupPacket& s, std::span<std::uint8_t> buffer) noexcept override;
  bool control_out(const SetupPacket& s, std::span<const std::uint8_t> data) noexcept override;
  void control_complete(const SetupPacket& s) noexcept override;
  bool configure(DeviceController& controller) noexcept override;
  void deconfigure() noexcept override;
  bool set_alternate(std::uint8_t interface, std::uint8_t alternate) noexcept override;
  std::uint8_t alternate(std::uint8_t) const noexcept override { return alternate_; }

  // bwPollTimeout as reported = the worst case x percent / 100, rounded up
  // to whole ms (so any non-zero percent still asks for >= 1 ms); 0 reports
  // 0 ms. Default 100. Takes effect from the next GETSTATUS.
  void set_poll_timeout_percent(std::uint32_t percent) noexcept { poll_percent_ = percent; }
  std::uint32_t poll_timeout_percent() const noexcept { return poll_percent_; }
  // Sum of the (unscaled) worst-case bwPollTimeouts of the operations run so
  // far, ms: what a host honouring the datasheet figures would have slept.
  std::uint64_t datasheet_poll_ms() const noexcept { return datasheet_poll_ms_; }

  dfu::State state() const noexcept { return state_; }
  dfu::Status status() const noexcept { return status_; }
  std::uint32_t address_pointer() const noexcept { return pointer_; }
  // True once the device has left the bus (leave or an injected vanish).
  bool left() const noexcept { return left_; }
  // The address the bootloader jumped to on "leave" (nullopt: no leave).
  std::optional<std::uint32_t> jump_address() const noexcept { return jump_address_; }
  // Requests seen: DNLOADs with data, of which DfuSe erase commands.
  std::size_t downloads() const noexcept { return downloads_; }
  std::size_t erase_commands() const noexcept { return erase_commands_; }

 private:
  enum class Pending : std::uint8_t { kNone, kCommand, kWrite, kLeave };
  ControlReply refuse() noexcept;  // STALL + dfuERROR errSTALLEDPKT
  ControlReply dnload(const SetupPacket& s) noexcept;
  ControlReply upload(const SetupPacket& s, std::span<std::uint8_t> buffer) noexcept;
  ControlReply get_status(std::span<std::uint8_t> buffer) noexcept;
  // Runs the stored command or write: the status it ends with, and
  // poll_ms_ set to its bwPollTimeout.
  dfu::Status run_command() noexcept;
  dfu::Status run_write() noexcept;
  void leave_bus() noexcept;

  RomFlashModel& flash_;
  const DfuseFaults& faults_;
  std::uint8_t interface_;
  std::uint8_t alternate_ = 0;
  DeviceController* controller_ = nullptr;

  dfu::State state_ = dfu::State::kIdle;
  dfu::Status status_ = dfu::Status::kOk;
  dfu::Status result_ = dfu::Status::kOk;  // of the operation the next GETSTATUS reports
  std::uint32_t poll_ms_ = 0;               // worst case of the operation, ms (unscaled)
  std::uint32_t poll_percent_ = 100;         // reported = poll_ms_ x poll_percent_ / 100
  std::uint64_t datasheet_poll_ms_ = 0;
  std::uint32_t pointer_ = RomFlashModel::kBase;  // the ROM's default: flash start

  Pending pending_ = Pending::kNone;
  std::uint16_t block_number_ = 0;
  std::size_t block_size_ = 0;
  std::array<std::uint8_t, kDfuseTransferSize> block_{};

  bool leave_after_status_ = false;
  bool vanish_after_status_ = false;
  bool left_ = false;
  std::optional<std::uint32_t> jump_address_;
  std::uint32_t stall_seen_ = 0;
  std::size_t downloads_ = 0;
  std::size_t erase_commands_ = 0;
};

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_DFUSE_SIM_DFUSE_ROM_INTERFACE_H_
