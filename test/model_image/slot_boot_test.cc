// The whole model-update path on the host with the firmware's own sources:
// an image written by the host's image writer, streamed into a simulated
// STM32F405 flash through ModelSlots, booted by the app's boot_model with
// its self-test, and run in place from the slot. A slot holding the
// built-in model runs bit for bit as the compiled-in model; a retrained
// model of the same shape runs its own tensors; an image whose self-test
// checksum is wrong is reverted. Tolerances: none (checksums equal).
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "codegen/codegen.h"
#include "firmware/app/model_store.h"
#include "firmware/flash/simulated_nor_flash.h"
#include "firmware/flash/stm32f405_flash_layout.h"
#include "hadynet_model_q15.h"
#include "host-sim/model_image/model_image_writer.h"

namespace {

using Q = hadynet::model_q15::Model;
namespace f405 = hadynet::flash::stm32f405;
namespace mu = hadynet::model_update;

const hadynet::codegen::LoadedModel& built_in() {
  static const hadynet::codegen::LoadedModel m = hadynet::codegen::load_model_file(HADYNET_MODEL_PATH);
  return m;
}

hadynet::codegen::GeneratedHeader header_of(const hadynet::trainer::HadynetModel& model,
                                            std::uint64_t model_hash = built_in().identity.hash) {
  hadynet::codegen::CodegenOptions o;
  o.target_formats = hadynet::host::firmware_formats<Q>();
  return hadynet::codegen::generate(model, {"retrained.safetensors", model_hash}, o);
}

// A device: the F405's flash (1 MiB, its sector table) and its slots.
struct Device {
  std::vector<std::uint8_t> cells = std::vector<std::uint8_t>(f405::kFlashSize);
  hadynet::flash::SimulatedNorFlash flash{f405::kSectors, cells};
  std::unique_ptr<mu::ModelSlots> slots;
  std::unique_ptr<hadynet::firmware::HadynetRuntime<Q>> runtime = std::make_unique<hadynet::firmware::HadynetRuntime<Q>>();

  explicit Device(const hadynet::host::PublicKey& key) { power_on(key); }
  void power_on(const hadynet::host::PublicKey& key) {
    slots = std::make_unique<mu::ModelSlots>(flash, hadynet::flash::FlashRegion{f405::kModelSlotAOffset, f405::kModelSlotSize},
                                             hadynet::flash::FlashRegion{f405::kModelSlotBOffset, f405::kModelSlotSize},
                                             hadynet::app::model_identity<Q>(), key, cells);
    runtime = std::make_unique<hadynet::firmware::HadynetRuntime<Q>>();
    hadynet::app::boot_model(*slots, *runtime);
  }
  mu::UpdateError send(const hadynet::host::ModelImage& image) {
    const std::span<const std::uint8_t> bytes(image.bytes);
    mu::UpdateError e = slots->begin_update(bytes.first(mu::kImageHeaderSize));
    for (std::size_t at = mu::kImageHeaderSize; e == mu::UpdateError::kOk && at < bytes.size(); at += 2048)
      e = slots->append_update(bytes.subspan(at, std::min<std::size_t>(2048, bytes.size() - at)));
    return e == mu::UpdateError::kOk ? slots->finish_update() : e;
  }
};

std::uint64_t checksum_of(hadynet::firmware::HadynetRuntime<Q>& runtime) {
  return hadynet::app::runtime_checksum(runtime);
}

TEST(SlotBoot, BuiltInModelFromASlotRunsBitForBitAsCompiledIn) {
  const auto key = hadynet::host::generate_signing_key(false);
  Device device(key.public_key);
  EXPECT_EQ(device.slots->choice().source, mu::ModelSource::kFactory);
  const auto image = hadynet::host::make_model_image<Q>(header_of(built_in().model), key, {1, false});
  ASSERT_EQ(device.send(image), mu::UpdateError::kOk);
  device.power_on(key.public_key);  // reboot: the new image's trial, self-test, confirmation
  const mu::BootChoice& choice = device.slots->choice();
  ASSERT_NE(choice.source, mu::ModelSource::kFactory);
  EXPECT_TRUE(choice.trial_this_boot);
  // The runtime reads the slot in place, not the compiled-in tensors.
  EXPECT_EQ(static_cast<const void*>(&device.runtime->tensors()), static_cast<const void*>(choice.payload.data()));
  auto compiled = std::make_unique<hadynet::firmware::HadynetRuntime<Q>>();
  EXPECT_EQ(checksum_of(*device.runtime), checksum_of(*compiled));
}

TEST(SlotBoot, RetrainedModelRunsItsOwnTensorsAndSurvivesReboots) {
  const auto key = hadynet::host::generate_signing_key(false);
  Device device(key.public_key);
  hadynet::trainer::HadynetModel changed = built_in().model;
  changed.params.dec_bias.array() += 0.01f;
  changed.params.pb.row(0).swap(changed.params.pb.row(1));
  constexpr std::uint64_t kRetrainedHash = 0x0123456789abcdefULL;
  const auto image = hadynet::host::make_model_image<Q>(header_of(changed, kRetrainedHash), key, {5, false});
  EXPECT_EQ(image.header.model_hash, kRetrainedHash);
  ASSERT_EQ(device.send(image), mu::UpdateError::kOk);
  for (int boot = 0; boot < 2; ++boot) {  // the trial boot, then a confirmed one
    device.power_on(key.public_key);
    ASSERT_NE(device.slots->choice().source, mu::ModelSource::kFactory) << "boot " << boot;
    EXPECT_EQ(device.slots->choice().trial_this_boot, boot == 0);
    EXPECT_EQ(device.runtime->tensors().model_hash, kRetrainedHash);  // what the link's INFO reports
    EXPECT_EQ(checksum_of(*device.runtime), image.self_test_checksum) << "boot " << boot;
  }
  auto compiled = std::make_unique<hadynet::firmware::HadynetRuntime<Q>>();
  EXPECT_NE(checksum_of(*compiled), image.self_test_checksum);
}

TEST(SlotBoot, ImageWhoseSelfTestFailsIsRevertedToTheFactoryModel) {
  const auto key = hadynet::host::generate_signing_key(false);
  Device device(key.public_key);
  auto image = hadynet::host::make_model_image<Q>(header_of(built_in().model), key, {1, false});
  // A validly signed header whose self-test checksum the model does not
  // reproduce (as if the host's and the device's runtimes disagreed).
  image.header.self_test_checksum ^= 1;
  std::array<std::uint8_t, mu::kImageHeaderSize> h{};
  mu::encode_model_image_header(image.header, h);
  image.header.signature = hadynet::host::sign(key, std::span<const std::uint8_t>(h.data(), mu::kSignedBytes));
  mu::encode_model_image_header(image.header, h);
  std::copy(h.begin(), h.end(), image.bytes.begin());
  ASSERT_EQ(device.send(image), mu::UpdateError::kOk);
  device.power_on(key.public_key);
  EXPECT_EQ(device.slots->choice().source, mu::ModelSource::kFactory);
  EXPECT_EQ(static_cast<const void*>(&device.runtime->tensors()),
            static_cast<const void*>(&hadynet::firmware::kCompiledTensors<Q>));
}

}  // namespace
