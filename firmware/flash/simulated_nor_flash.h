// A NOR flash in RAM behind the flash seam, for tests and the fuzzer: erased
// bytes read 0xFF, programming only clears bits, programming over
// non-erased bytes or across a sector boundary is refused (kNotErased,
// kCrossesSector), and faults can be scheduled by operation number:
//
//   * power cut at operation N: operation N does half its work (an erase
//     sets the first half of the sector to 0xFF and leaves the rest; a
//     program writes the first half of its bytes) and returns kPowerLoss;
//     every later operation (reads too) returns kPowerLoss until power_on()
//     (the reboot). The contents stay as they are (non-volatile).
//   * write error at operation N: operation N changes nothing and returns
//     kWriteError (a controller error flag); later operations work.
//
// Operations are erase_sector() and program() calls, numbered from 1 in
// operation_count() (reads are not counted). The storage and the sector
// table belong to the caller (no heap).
#ifndef HADYNET_FIRMWARE_FLASH_SIMULATED_NOR_FLASH_H_
#define HADYNET_FIRMWARE_FLASH_SIMULATED_NOR_FLASH_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/flash/flash_device.h"

namespace hadynet::flash {

class SimulatedNorFlash final : public FlashDevice {
 public:
  // `storage` must hold the sectors' total size; it is erased (0xFF) here.
  SimulatedNorFlash(std::span<const FlashSector> sectors, std::span<std::uint8_t> storage,
                    std::uint32_t program_alignment = 4, std::uint32_t program_max_us_per_byte = 25) noexcept;

  std::span<const FlashSector> sectors() const noexcept override { return sectors_; }
  std::uint32_t program_alignment() const noexcept override { return alignment_; }
  std::uint32_t program_max_us_per_byte() const noexcept override { return program_us_per_byte_; }
  FlashStatus erase_sector(std::size_t index) noexcept override;
  FlashStatus program(std::uint32_t offset, std::span<const std::uint8_t> data) noexcept override;
  FlashStatus read(std::uint32_t offset, std::span<std::uint8_t> out) const noexcept override;

  // Faults by operation number (1 = the next operation after reset of the
  // counter); 0 = none.
  void cut_power_at(std::uint64_t operation) noexcept { power_cut_at_ = operation; }
  void fail_write_at(std::uint64_t operation) noexcept { write_error_at_ = operation; }
  void power_on() noexcept { powered_ = true; }
  bool powered() const noexcept { return powered_; }
  std::uint64_t operation_count() const noexcept { return operations_; }
  std::uint64_t erase_count() const noexcept { return erases_; }

  // Direct view of the cells (tests).
  std::span<const std::uint8_t> contents() const noexcept { return storage_; }

 private:
  enum class Fault : std::uint8_t { kNone, kPowerCut, kWriteError };
  Fault next_operation() noexcept;

  std::span<const FlashSector> sectors_;
  std::span<std::uint8_t> storage_;
  std::uint32_t alignment_;
  std::uint32_t program_us_per_byte_;
  std::uint64_t operations_ = 0;
  std::uint64_t erases_ = 0;
  std::uint64_t power_cut_at_ = 0;
  std::uint64_t write_error_at_ = 0;
  bool powered_ = true;
};

}  // namespace hadynet::flash

#endif  // HADYNET_FIRMWARE_FLASH_SIMULATED_NOR_FLASH_H_
