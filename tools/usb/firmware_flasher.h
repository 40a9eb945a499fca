// Writes a firmware image into an MCU through its DfuSe bootloader (the
// STM32 ROM's, AN3156): checks the image against the memory layout the
// bootloader names (before touching anything), erases exactly the sectors
// the image covers, writes it in wTransferSize blocks, reads every byte back
// and compares (dfu-util has no verify), then leaves: the MCU starts the new
// firmware. Progress goes to a callback (bytes done of total, per phase).
#ifndef HADYNET_TOOLS_USB_FIRMWARE_FLASHER_H_
#define HADYNET_TOOLS_USB_FIRMWARE_FLASHER_H_

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>

#include "tools/usb/dfu_client.h"
#include "tools/usb/dfuse_memory_layout.h"
#include "tools/usb/firmware_image.h"

namespace hadynet::tools::usb {

enum class FlashPhase { kErase, kWrite, kVerify };
const char* phase_name(FlashPhase p);

struct FlashProgress {
  FlashPhase phase = FlashPhase::kErase;
  std::uint64_t done = 0;   // bytes of this phase done
  std::uint64_t total = 0;  // bytes of this phase
};

struct FlashResult {
  std::uint32_t sectors_erased = 0;
  std::uint64_t bytes_written = 0;
  std::uint64_t bytes_verified = 0;
};

// A flash that did not complete. what() says what happened, what the flash
// now holds and what to do; exit_code() is the command's exit status:
//   3 the image does not fit (nothing was touched)
//   4 the device vanished mid-way      5 the device reported an error
//   6 verify mismatch                  7 any other transfer failure
class FlashError : public std::runtime_error {
 public:
  FlashError(int exit_code, const std::string& what) : std::runtime_error(what), exit_code_(exit_code) {}
  int exit_code() const { return exit_code_; }

 private:
  int exit_code_;
};

class FirmwareFlasher {
 public:
  using Progress = std::function<void(const FlashProgress&)>;
  // `transfer_size`: the DFU functional descriptor's wTransferSize (bytes).
  FirmwareFlasher(DfuClient& client, DfuseMemoryLayout layout, std::uint16_t transfer_size, Progress progress)
      : client_(client), layout_(std::move(layout)), transfer_size_(transfer_size), progress_(std::move(progress)) {}

  // Erase, write, verify, leave. Throws FlashError.
  FlashResult flash(const FirmwareImage& image);
  // Erase, write, verify; the device stays in the bootloader.
  FlashResult write_and_verify(const FirmwareImage& image);
  // The DfuSe leave: start the firmware at `address`.
  void leave(std::uint32_t address);

 private:
  std::vector<const DfuseSector*> plan(const FirmwareImage& image) const;

  DfuClient& client_;
  DfuseMemoryLayout layout_;
  std::uint16_t transfer_size_;
  Progress progress_;
};

}  // namespace hadynet::tools::usb

#endif  // HADYNET_TOOLS_USB_FIRMWARE_FLASHER_H_
