// hadynet flash: firmware into the forearm MCU through the STM32 ROM DfuSe
// bootloader (a running hand is sent there by DFU_DETACH first), erased,
// written, read back and verified (tools/usb/firmware_flasher.h); or, with
// --model, a signed model image (hadynet model-image) through the
// firmware's own DFU model interface into the model slot not in use, read
// back and compared; the device's refusal, if any, in its own words.
#include <libusb.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/options.h"
#include "firmware/usb/composite_descriptors.h"
#include "firmware/usb/dfu_mode.h"
#include "firmware/usb/usb_identity.h"
#include "hadynet_model_q15.h"
#include "host-sim/model_image/signing_key.h"
#include "tools/usb/dfu_client.h"
#include "tools/usb/dfuse_memory_layout.h"
#include "tools/usb/firmware_flasher.h"
#include "tools/usb/firmware_image.h"
#include "tools/usb/libusb_dfu.h"
#include "tools/usb/model_image_file.h"
#include "tools/usb/usb_inventory.h"

namespace hadynet::cli {
namespace {

namespace tu = tools::usb;
using Clock = std::chrono::steady_clock;

constexpr double kBootloaderWaitS = 10.0;  // after DFU_DETACH: the ROM enumerates within ~1 s

struct ContextCloser {
  void operator()(libusb_context* c) const { libusb_exit(c); }
};
struct ListDeleter {
  void operator()(libusb_device** l) const { libusb_free_device_list(l, 1); }
};

// The progress bar on stderr: phase, bar, percent, bytes, rate, ETA.
class ProgressBar {
 public:
  explicit ProgressBar(bool quiet) : quiet_(quiet) {}
  void operator()(const tu::FlashProgress& p) {
    if (quiet_ || p.total == 0) return;
    if (p.phase != phase_ || p.done == 0) {
      phase_ = p.phase;
      start_ = Clock::now();
    }
    const double s = std::chrono::duration<double>(Clock::now() - start_).count();
    const double rate = s > 0 ? static_cast<double>(p.done) / s : 0;
    const double eta = rate > 0 ? static_cast<double>(p.total - p.done) / rate : 0;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(kWidth * p.done / p.total);
    std::fprintf(stderr, "\r%-6s [%s%s] %3d%%  %7llu/%llu B  %6.1f kB/s  ETA %4.0f s", tu::phase_name(p.phase),
                 std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(kWidth - filled), ' ').c_str(),
                 static_cast<int>(100 * p.done / p.total), static_cast<unsigned long long>(p.done),
                 static_cast<unsigned long long>(p.total), rate / 1000, eta);
    if (p.done == p.total) std::fputc('\n', stderr);
    std::fflush(stderr);
  }

 private:
  bool quiet_;
  tu::FlashPhase phase_ = tu::FlashPhase::kErase;
  Clock::time_point start_ = Clock::now();
};

// The libusb_device with this bus/address (a reference the caller unrefs), or nullptr.
libusb_device* device_at(libusb_context* ctx, std::uint8_t bus, std::uint8_t address) {
  libusb_device** raw = nullptr;
  const ssize_t n = libusb_get_device_list(ctx, &raw);
  if (n < 0) return nullptr;
  const std::unique_ptr<libusb_device*, ListDeleter> list(raw);
  for (ssize_t i = 0; i < n; ++i) {
    if (libusb_get_bus_number(raw[i]) == bus && libusb_get_device_address(raw[i]) == address) {
      return libusb_ref_device(raw[i]);
    }
  }
  return nullptr;
}

struct DeviceRef {
  libusb_device* device = nullptr;
  ~DeviceRef() {
    if (device != nullptr) libusb_unref_device(device);
  }
};

std::string serials_of(const std::vector<tu::AttachedDevice>& devices, tu::AttachedDevice::Kind kind) {
  std::string s;
  for (const auto& d : devices) {
    if (d.kind == kind) s += (s.empty() ? "" : ", ") + (d.serial.empty() ? std::string("?") : d.serial);
  }
  return s;
}

// The one device of `kind` (matching `serial` if given); nullopt if none.
std::optional<tu::AttachedDevice> pick(const std::vector<tu::AttachedDevice>& devices, tu::AttachedDevice::Kind kind,
                                       const std::string& serial, const char* what) {
  std::vector<tu::AttachedDevice> matches;
  for (const auto& d : devices) {
    if (d.kind == kind && (serial.empty() || d.serial == serial)) matches.push_back(d);
  }
  if (matches.empty()) return std::nullopt;
  if (matches.size() > 1) {
    throw std::runtime_error(std::to_string(matches.size()) + " " + what + "s attached (serials " +
                             serials_of(devices, kind) + "): choose one with --serial");
  }
  if (matches[0].access_denied) {
    throw std::runtime_error(std::string("permission denied on the ") + what +
                             ": install udev/60-hadynet.rules (docs/usb.md) and re-plug");
  }
  return matches[0];
}

int flash_firmware(libusb_context* ctx, const Options& opt, const std::string& file) {
  const tu::FirmwareImage image = tu::load_firmware_image(file);
  const std::string serial = opt.get("serial");
  auto devices = tu::list_attached_devices(ctx);
  auto rom = pick(devices, tu::AttachedDevice::Kind::kRomBootloader, "", "STM32 ROM bootloader");
  if (!rom) {
    const auto hand = pick(devices, tu::AttachedDevice::Kind::kHand, serial, "HADYNET hand");
    if (!hand) {
      std::fprintf(stderr,
                   "hadynet flash: no HADYNET hand%s and no STM32 ROM bootloader (0483:df11) on USB (see hadynet "
                   "devices); a board without working firmware: hold BOOT0 high and reset it\n",
                   serial.empty() ? "" : (" with serial " + serial).c_str());
      return 1;
    }
    DeviceRef dev{device_at(ctx, hand->bus, hand->address)};
    if (dev.device == nullptr) throw std::runtime_error("the hand left the bus before it could be detached");
    const int runtime = tu::find_dfu_interface(dev.device, usb::dfu::kProtocolRuntime);
    if (runtime < 0) throw std::runtime_error("the hand offers no DFU runtime interface (old firmware?)");
    std::fprintf(stderr, "hadynet flash: hand %s: DFU_DETACH into the ROM bootloader...\n", hand->serial.c_str());
    tu::detach_to_bootloader(dev.device, static_cast<std::uint8_t>(runtime));
    const auto start = Clock::now();
    while (!rom) {
      if (std::chrono::duration<double>(Clock::now() - start).count() > kBootloaderWaitS) {
        std::fprintf(stderr,
                     "hadynet flash: the ROM bootloader (0483:df11) did not appear within %.0f s of DFU_DETACH; if "
                     "the hand is still running its firmware, hold BOOT0 high and reset it\n",
                     kBootloaderWaitS);
        return 4;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      devices = tu::list_attached_devices(ctx);
      rom = pick(devices, tu::AttachedDevice::Kind::kRomBootloader, "", "STM32 ROM bootloader");
    }
  }
  DeviceRef dev{device_at(ctx, rom->bus, rom->address)};
  if (dev.device == nullptr) throw std::runtime_error("the ROM bootloader left the bus before it could be opened");
  const int dfu_interface = tu::find_dfu_interface(dev.device, usb::dfu::kProtocolDfuMode);
  if (dfu_interface < 0) throw std::runtime_error("the bootloader offers no DFU-mode interface");
  tu::LibusbDfuInterface dfu(dev.device, static_cast<std::uint8_t>(dfu_interface), /*alternate=*/0);
  std::string error;
  const auto layout = tu::parse_dfuse_memory_layout(dfu.alternate_names().empty() ? "" : dfu.alternate_names()[0], error);
  if (!layout) throw std::runtime_error("the bootloader's alternate setting 0 is not a DfuSe memory: " + error);
  std::fprintf(stderr, "hadynet flash: %s, %zu bytes to 0x%08x (%s, wTransferSize %u)\n", file.c_str(),
               image.bytes.size(), image.address, layout->name.c_str(), dfu.functional().transfer_size);

  tu::DfuClient client(dfu, [](std::uint32_t ms) { std::this_thread::sleep_for(std::chrono::milliseconds(ms)); });
  ProgressBar bar(opt.has("quiet"));
  tu::FirmwareFlasher flasher(client, *layout, dfu.functional().transfer_size, std::ref(bar));
  const auto start = Clock::now();
  const tu::FlashResult r = opt.has("no-leave") ? flasher.write_and_verify(image) : flasher.flash(image);
  const double s = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf("flashed %s: %llu bytes written and verified byte for byte, %u sectors erased, %.1f s (%.1f kB/s)%s\n",
              file.c_str(), static_cast<unsigned long long>(r.bytes_written), r.sectors_erased, s,
              s > 0 ? static_cast<double>(r.bytes_written) / s / 1000 : 0.0,
              opt.has("no-leave") ? "; the MCU stays in the bootloader" : "; the MCU starts it now");
  return 0;
}

// What the image says about itself, before anything is sent.
void describe_image(const std::string& file, const tu::ModelImageFile& image) {
  const model_update::ModelImageHeader& h = image.header;
  const bool ours = h.shape_id == model_q15::Model::kShapeId;
  std::printf("model image %s: sequence %u%s, %s, shape id %016llx (%s), payload %u bytes, model %016llx\n",
              file.c_str(), h.sequence, h.downgrade_allowed ? " (downgrade allowed)" : "",
              h.numeric == model_update::kNumericQ15 ? "q15" : "f32", static_cast<unsigned long long>(h.shape_id),
              ours ? "this build's firmware" : "NOT this build's q15 firmware: a hand built from it refuses it",
              h.payload_length, static_cast<unsigned long long>(h.model_hash));
  std::printf("  signed by %s%s\n", host::hex(h.public_key).c_str(),
              tu::is_development_key(h.public_key)
                  ? " -- the DEVELOPMENT key (keys/): anyone can sign images a hand that trusts it accepts"
                  : "");
  std::fflush(stdout);
}

// The device's description of its last DFU status (GETSTATUS iString), or "".
std::string device_text(tu::LibusbDfuInterface& dfu, std::uint8_t index) {
  try {
    return dfu.string_descriptor(index);
  } catch (const std::exception&) {
    return {};
  }
}

int flash_model(libusb_context* ctx, const Options& opt, const std::string& file) {
  // Checked before any device is touched.
  const tu::ModelImageFile image = tu::load_model_image_file(file);
  describe_image(file, image);
  const std::vector<std::uint8_t>& bytes = image.bytes;
  const auto devices = tu::list_attached_devices(ctx);
  const auto hand = pick(devices, tu::AttachedDevice::Kind::kHand, opt.get("serial"), "HADYNET hand");
  if (!hand) {
    std::fprintf(stderr, "hadynet flash --model: no HADYNET hand on USB (see hadynet devices)\n");
    return 1;
  }
  DeviceRef dev{device_at(ctx, hand->bus, hand->address)};
  if (dev.device == nullptr) throw std::runtime_error("the hand left the bus before it could be opened");
  tu::LibusbDfuInterface dfu(dev.device, usb::composite::kDfuModeInterface, usb::kDfuAltModelUpdate);
  const std::uint16_t xfer = dfu.functional().transfer_size;
  tu::DfuClient client(dfu, [](std::uint32_t ms) { std::this_thread::sleep_for(std::chrono::milliseconds(ms)); });
  ProgressBar bar(opt.has("quiet"));
  constexpr const char* kUnchanged = "the model in use and the boot choice are unchanged";
  try {
    client.ensure_idle();
    std::uint16_t block = 0;
    for (std::size_t at = 0; at < bytes.size(); at += xfer, ++block) {
      const std::size_t n = std::min<std::size_t>(xfer, bytes.size() - at);
      client.download(block, std::span(bytes).subspan(at, n));
      bar({tu::FlashPhase::kWrite, at + n, bytes.size()});
    }
    client.manifest();
    const std::string result = device_text(dfu, client.get_status().string_index);
    std::vector<std::uint8_t> back, chunk(xfer);
    for (std::uint16_t b = 0;; ++b) {
      const std::size_t n = client.upload(b, chunk);
      back.insert(back.end(), chunk.begin(), chunk.begin() + static_cast<std::ptrdiff_t>(n));
      bar({tu::FlashPhase::kVerify, std::min(back.size(), bytes.size()), bytes.size()});
      if (n < xfer || back.size() > bytes.size()) break;
    }
    client.abort();  // back to dfuIDLE whether the upload ended on a short block or not
    if (back != bytes) {
      std::fprintf(stderr,
                   "hadynet flash --model: the slot reads back %zu bytes that differ from the %zu sent: the slot "
                   "does not hold this image (the boot rule will not run it unless it verifies); send it again\n",
                   back.size(), bytes.size());
      return 6;
    }
    std::printf("model %s: %zu bytes sent to hand %s and read back byte for byte%s%s\n", file.c_str(), bytes.size(),
                hand->serial.c_str(), result.empty() ? "" : ": ", result.c_str());
    std::printf("the new model runs after the next reset or power-up: the boot rule tries it then (self-test, then "
                "confirmed, or reverted to the model in use now)\n");
  } catch (const tu::DfuError& e) {
    const std::string why = device_text(dfu, e.status().string_index);
    if (why.empty()) {
      std::fprintf(stderr, "hadynet flash --model: %s; %s\n", e.what(), kUnchanged);
    } else {
      std::fprintf(stderr, "hadynet flash --model: the image was not taken: %s (%s); %s\n", why.c_str(), e.what(),
                   kUnchanged);
    }
    try {
      client.clear_status();
    } catch (const std::exception&) {
    }
    return 5;
  } catch (const tu::UsbTransferError& e) {
    // A request the hand STALLs (e.g. DNLOAD on a hand without model slots)
    // leaves it in dfuERROR with its reason: ask for it.
    if (e.kind() == tu::UsbTransferError::Kind::kStall) {
      try {
        const tu::DfuStatus st = client.get_status();
        const std::string why = device_text(dfu, st.string_index);
        if (st.state == tu::dfu::State::kError && !why.empty()) {
          std::fprintf(stderr, "hadynet flash --model: the image was not taken: %s (%s: %s); %s\n", why.c_str(),
                       e.what(), tu::status_name(st.status), kUnchanged);
          client.clear_status();
          return 5;
        }
      } catch (const std::exception&) {
      }
    }
    std::fprintf(stderr, "hadynet flash --model: %s; %s (an interrupted image is never run)\n", e.what(), kUnchanged);
    return e.kind() == tu::UsbTransferError::Kind::kGone ? 4 : 7;
  }
  return 0;
}

}  // namespace

int run_flash(int argc, char** argv) {
  Options opt("flash",
              "Writes firmware into the forearm MCU over USB: a running hand is sent into the STM32 ROM DfuSe\n"
              "bootloader (DFU_DETACH; or use one already there: BOOT0 high + reset), only the sectors the\n"
              "image covers are erased, the image is written, read back and compared byte for byte, and the\n"
              "MCU starts it. FILE: the .elf (its load segments) or the .bin (at 0x08000000) of a build.\n"
              "--model IMAGE instead sends a signed model image (hadynet model-image; docs/usb.md, \"Model\n"
              "images\") to the running firmware's DFU model interface. The file is checked first (a model\n"
              "image header, the right length; its sequence, shape id, payload size and signing key are\n"
              "printed); the hand checks the header (model shape, key, signature, a sequence newer than its\n"
              "newest image) before it erases anything, writes it into the slot not in use, and the image\n"
              "is read back and compared. A refusal is printed in the hand's words (\"signed by another\n"
              "key\", \"model shape does not match the firmware\", ...). The new model runs after the next\n"
              "reset or power-up, when the boot rule tries it (self-test, then confirmed or reverted).\n"
              "Exit status: 0 done, 1 no device / bad input, 2 usage, 3 image does not fit (nothing\n"
              "touched), 4 device vanished, 5 device reported an error (or refused the model image),\n"
              "6 verify mismatch, 7 other USB error.",
              "FIRMWARE.elf|.bin [--serial S] | --model IMAGE [--serial S]");
  opt.value("serial", "S", "the hand's serial number (hadynet devices), if several are attached");
  opt.value("model", "IMAGE", "send a signed model image into the hand's free model slot instead of firmware");
  opt.flag("no-leave", "stay in the bootloader after the verify (do not start the firmware)");
  opt.flag("quiet", "no progress bar");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  const bool model = opt.has("model");
  if (model != opt.positional().empty() || opt.positional().size() > 1) {
    std::fprintf(stderr, "hadynet flash: give a FIRMWARE file or --model FILE (see --help)\n");
    return 2;
  }
  libusb_context* raw = nullptr;
  if (const int r = libusb_init(&raw); r != LIBUSB_SUCCESS) {
    std::fprintf(stderr, "hadynet flash: libusb cannot start: %s\n", libusb_strerror(r));
    return 1;
  }
  const std::unique_ptr<libusb_context, ContextCloser> ctx(raw);
  try {
    return model ? flash_model(ctx.get(), opt, opt.get("model")) : flash_firmware(ctx.get(), opt, opt.positional()[0]);
  } catch (const tu::FlashError& e) {
    std::fprintf(stderr, "\nhadynet flash: %s\n", e.what());
    return e.exit_code();
  } catch (const tu::ModelImageFileError& e) {
    std::fprintf(stderr, "hadynet flash --model: %s; nothing was sent\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "\nhadynet flash: %s\n", error_text(e).c_str());
    return 1;
  }
}

}  // namespace hadynet::cli
