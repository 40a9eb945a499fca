// The USB fuzzer's model slots (usb_fuzz_harness.h): a small flash whose two
// slots the fuzzer can fill within one input, the model identity the slots
// accept, and the public key images must be signed with. Its secret half is
// libsodium's crypto_sign_seed_keypair of 32 bytes 0x46 (kFuzzKeySeedByte):
// the seeds (usb_fuzz_seeds.h) sign with it, and test/usb/fuzz_seed_test.cc
// checks that the two halves belong together.
#ifndef HADYNET_FUZZ_USB_FUZZ_MODEL_H_
#define HADYNET_FUZZ_USB_FUZZ_MODEL_H_

#include <array>
#include <cstddef>
#include <cstdint>

#include "firmware/flash/flash_device.h"
#include "firmware/flash/flash_region_writer.h"
#include "firmware/model_update/model_identity.h"
#include "firmware/model_update/model_image.h"

namespace hadynet::usb::fuzz {

// 1 KiB sectors 0..3 (0..1 "firmware", 2..3 slot A), one 2 KiB sector (slot
// B): the two slots are equal in size but not in sector layout. Erase times
// small: a DFU poll time is just a number here.
inline constexpr flash::FlashSector kFuzzSectors[] = {
    {0, 1024, 5}, {1024, 1024, 5}, {2048, 1024, 5}, {3072, 1024, 5}, {4096, 2048, 10}};
inline constexpr std::size_t kFuzzFlashBytes = 6144;
inline constexpr flash::FlashRegion kFuzzSlotA{2048, 2048};
inline constexpr flash::FlashRegion kFuzzSlotB{4096, 2048};

// A model of 700 payload bytes (1024 + 700 fits a 2 KiB slot).
inline constexpr std::size_t kFuzzPayloadBytes = 700;
constexpr model_update::ModelIdentity fuzz_identity() noexcept {
  model_update::ModelIdentity id;
  id.contract_version = 4;
  id.numeric = model_update::kNumericQ15;
  id.shape_id = 0xF022F022F022F022ull;
  id.payload_length = static_cast<std::uint32_t>(kFuzzPayloadBytes);
  return id;
}

inline constexpr std::uint8_t kFuzzKeySeedByte = 0x46;
inline constexpr model_update::PublicKey kFuzzPublicKey = {
    0xee, 0x93, 0xa4, 0xf6, 0x6f, 0x8d, 0x16, 0xb8, 0x19, 0xbb, 0x9b, 0xeb, 0x9f, 0xfc, 0xcd, 0xfc,
    0xdc, 0x14, 0x12, 0xe8, 0x7f, 0xee, 0x6a, 0x32, 0x4c, 0x2a, 0x99, 0xa1, 0xe0, 0xe6, 0x71, 0x48};

}  // namespace hadynet::usb::fuzz

#endif  // HADYNET_FUZZ_USB_FUZZ_MODEL_H_
