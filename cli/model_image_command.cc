// hadynet model-image: a trained model -> a signed model image for this
// build's firmware (docs/model-update.md), which `hadynet flash --model`
// sends to the device's model slots.
#include <cstdio>
#include <filesystem>
#include <string>

#include "cli/codegen_command_line.h"
#include "cli/commands.h"
#include "cli/options.h"
#include "codegen/codegen.h"
#include "datalog/atomic_file.h"
#include "firmware/flash/stm32f405_flash_layout.h"
#include "firmware/model_update/slot_layout.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "host-sim/model_image/model_image_writer.h"

namespace hadynet::cli {

namespace {

template <class M>
host::ModelImage image_for(const codegen::LoadedModel& loaded, codegen::CodegenOptions options,
                           const host::SigningKey& key, const host::ModelImageRequest& request) {
  options.numeric = M::kNumeric;
  if (M::kNumeric == firmware::Numeric::kQ15) options.target_formats = host::firmware_formats<M>();
  const codegen::GeneratedHeader header = codegen::generate(loaded.model, loaded.identity, options);
  return host::make_model_image<M>(header, key, request);
}

}  // namespace

int run_model_image(int argc, char** argv) {
  cli::Options opt(
      "model-image",
      "Writes a signed model image of MODEL for this build's firmware: the model's weights,\n"
      "standardisation, PB table, detection statistics and sensor model in the firmware's own\n"
      "layout and formats, after a header with the firmware's shape id, a sequence number, the\n"
      "payload's SHA-256, the self-test checksum the device must reproduce before it confirms the\n"
      "image, and an Ed25519 signature (docs/model-update.md). A model of another shape (channels,\n"
      "dimensions, sensor model, stabiliser options) or needing more range than the firmware's\n"
      "fixed-point formats is refused: it needs a firmware built for it. Give the codegen options\n"
      "the firmware's header was generated with (the defaults, unless the build set\n"
      "HADYNET_CODEGEN_OPTIONS).",
      "MODEL --out IMAGE --key KEY --sequence N [--numeric q15|f32] [--allow-downgrade] [codegen options]");
  opt.value("out", "IMAGE", "image file to write");
  opt.value("key", "KEY", "secret key file (hadynet keygen; keys/development.key for development)");
  opt.value("sequence", "N", "sequence number, >= 1: the device takes only images newer than its newest");
  opt.value("numeric", "q15|f32", "the firmware's numeric (f32 images are larger than an F405 slot)", "q15");
  opt.flag("allow-downgrade",
           "sign the image as allowed to replace a newer one (the device then invalidates the other slot)");
  add_model_options(opt);
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  const std::string who = "hadynet model-image";
  if (opt.positional().size() != 1 || !opt.has("out") || !opt.has("key") || !opt.has("sequence")) {
    std::fprintf(stderr, "%s: give MODEL, --out, --key and --sequence (see --help)\n", who.c_str());
    return 2;
  }
  const auto sequence = opt.get_int("sequence", 1, 0xFFFFFFFFll);
  const auto numeric = opt.get_numeric("numeric");
  codegen::CodegenOptions options;
  if (!sequence || !numeric || !read_model_options(opt, who, options)) return 2;
  try {
    const codegen::LoadedModel loaded = codegen::load_model_file(opt.positional().front());
    const host::SigningKey key = host::read_signing_key(opt.get("key"));
    const host::ModelImageRequest request{static_cast<std::uint32_t>(*sequence), opt.has("allow-downgrade")};
    const host::ModelImage image = *numeric == firmware::Numeric::kQ15
                                       ? image_for<model_q15::Model>(loaded, options, key, request)
                                       : image_for<model_f32::Model>(loaded, options, key, request);
    datalog::write_file_atomically(
        opt.get("out"), std::string_view(reinterpret_cast<const char*>(image.bytes.data()), image.bytes.size()));
    const model_update::ModelImageHeader& h = image.header;
    const std::uint32_t capacity = flash::stm32f405::kModelSlotSize - model_update::kSlotPayloadOffset;
    std::printf("%s: %s model image, sequence %u%s, shape id %016llx, payload %u bytes (F405 slot: %u)\n",
                opt.get("out").c_str(), firmware::numeric_name(*numeric), h.sequence,
                h.downgrade_allowed ? " (downgrade allowed)" : "", static_cast<unsigned long long>(h.shape_id),
                h.payload_length, capacity);
    std::printf("  model %s (FNV-1a 64 %016llx), self-test checksum %08x\n", opt.positional().front().c_str(),
                static_cast<unsigned long long>(h.model_hash), h.self_test_checksum);
    std::printf("  signed by %s%s\n", host::hex(key.public_key).c_str(),
                key.development ? " -- a DEVELOPMENT key: anyone can sign images a firmware with it accepts" : "");
    if (h.payload_length > capacity)
      std::printf("  note: larger than an STM32F405 model slot; usable in host-sim only\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", who.c_str(), e.what());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
