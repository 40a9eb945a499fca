// How long the DFU model interface tells the host to wait (bwPollTimeout)
// while service() does an update's work, and which flash operation failed
// when an update reports a flash error. Both follow how ModelSlots streams
// a payload into a slot (firmware/model_update/slot_update_stream.h, through
// flash::FlashRegionWriter): payload from slot offset 1024; sectors erased
// from the slot's start, each when the first program reaches it (so the
// first payload bytes also erase the header's sector); programs in the
// flash's program units, split at sector boundaries; a partial unit held
// until more bytes come.
//
// Times (the F405; docs/usb.md, "Timings"):
//   * a block: the worst-case erase of every sector it reaches first plus
//     its bytes at the worst-case programming rate (flash_device.h; the F405
//     table: 4000 ms per 128 KiB sector, 25 us/byte). Hashing the block
//     (SHA-256, 69 instructions/byte: 18 k instructions, 0.1 ms at 168 MHz)
//     hides in the datasheet's programming margin (100 us per word worst
//     case against 16 us typical).
//   * the block that completes the 256-byte header adds kDfuHeaderCheckMs:
//     begin_update() verifies the header's Ed25519 signature.
//   * manifestation: kDfuManifestMs covers finish_update().
#ifndef HADYNET_FIRMWARE_USB_DFU_UPDATE_TIMING_H_
#define HADYNET_FIRMWARE_USB_DFU_UPDATE_TIMING_H_

#include <cstddef>
#include <cstdint>

#include "firmware/flash/flash_device.h"
#include "firmware/flash/flash_region_writer.h"
#include "firmware/model_update/counting_flash.h"

namespace hadynet::usb {

// begin_update(): one Ed25519 verification, 3.0 M instructions on the
// Cortex-M4 (bench/model_update_icount.sh under QEMU -icount: 18 ms at one
// instruction per cycle at 168 MHz). NOT measured on the F405 yet (flash
// wait states, the ART cache); 250 ms leaves a margin of 14x over the count.
inline constexpr std::uint32_t kDfuHeaderCheckMs = 250;

// finish_update(): the payload hashed twice (SHA-256 of the flash read back,
// and again in the mapped view by the slot check), one Ed25519 verification
// (the slot check), the 256-byte header programmed and read back (6.4 ms
// worst case), and for a forced downgrade one 16-byte flag (0.4 ms). For
// the hand's payload (181 032 bytes when measured, 172 856 since contract
// 7; 69 instructions/byte) 25 M + 3 M instructions, 167 ms at one
// instruction per cycle at 168 MHz; for a payload filling a whole F405
// slot (261 120 bytes) 39 M, 233 ms. NOT measured on the F405 yet (the
// colleague writing the crypto measures it on the Cortex-M4); 2000 ms
// leaves a margin of 8.5x over the whole-slot count and is short enough
// that a host waits for it without a complaint.
inline constexpr std::uint32_t kDfuManifestMs = 2000;

// Worst-case flash time, ms (rounded up), of appending `bytes` payload bytes
// to a stream into `slot` that has accepted `written` payload bytes so far.
std::uint32_t payload_append_ms(const flash::FlashDevice& flash, const flash::FlashRegion& slot,
                                std::uint32_t written, std::size_t bytes) noexcept;

// After an append of `bytes` payload bytes (with `written` accepted before
// it) ended in a flash error: whether the operation that failed was an
// erase (else a program). `done` counts the erases and programmed bytes the
// flash completed during that append (ModelSlots::update_counters() after
// minus before). Exact: the stream's operations come in a fixed order, and
// every operation before the failing one completed.
bool append_failed_in_erase(const flash::FlashDevice& flash, const flash::FlashRegion& slot, std::uint32_t written,
                            std::size_t bytes, const model_update::FlashCounters& done) noexcept;

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_DFU_UPDATE_TIMING_H_
