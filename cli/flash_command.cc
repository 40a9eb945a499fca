// hadynet flash: firmware into the forearm MCU through the STM32 ROM DfuSe
// bootloader (a running hand is sent there by DFU_DETACH first), erased,
// written, read back and verified (tools/usb/firmware_flasher.h); or, with
// --model, a model file into the firmware's inactive model slot through its
// own DFU interface, read back and compared.
#include <libusb.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <thread>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/options.h"
#include "firmware/link/crc32.h"
#include "firmware/usb/composite_descriptors.h"
#include "firmware/usb/dfu_image.h"
#include "firmware/usb/usb_identity.h"
#include "tools/usb/dfu_client.h"
#include "tools/usb/dfuse_memory_layout.h"
#include "tools/usb/firmware_flasher.h"
#include "tools/usb/firmware_image.h"
#include "tools/usb/libusb_dfu.h"
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

// The model file in the DFU envelope (firmware/usb/dfu_image.h).
std::vector<std::uint8_t> model_envelope(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file + ": cannot open");
  std::vector<std::uint8_t> payload((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (payload.empty()) throw std::runtime_error(file + ": empty file");
  usb::DfuImageHeader h;
  h.length = static_cast<std::uint32_t>(payload.size());
  h.crc32 = link::crc32(payload);
  std::vector<std::uint8_t> bytes(usb::kDfuImageHeaderSize + payload.size());
  usb::encode_dfu_image_header(h, std::span<std::uint8_t, usb::kDfuImageHeaderSize>(bytes.data(), usb::kDfuImageHeaderSize));
  std::copy(payload.begin(), payload.end(), bytes.begin() + usb::kDfuImageHeaderSize);
  return bytes;
}

int flash_model(libusb_context* ctx, const Options& opt, const std::string& file) {
  const std::vector<std::uint8_t> bytes = model_envelope(file);
  const auto devices = tu::list_attached_devices(ctx);
  const auto hand = pick(devices, tu::AttachedDevice::Kind::kHand, opt.get("serial"), "HADYNET hand");
  if (!hand) {
    std::fprintf(stderr, "hadynet flash --model: no HADYNET hand on USB (see hadynet devices)\n");
    return 1;
  }
  DeviceRef dev{device_at(ctx, hand->bus, hand->address)};
  if (dev.device == nullptr) throw std::runtime_error("the hand left the bus before it could be opened");
  tu::LibusbDfuInterface dfu(dev.device, usb::composite::kDfuModeInterface, /*alternate=*/0);
  const std::uint16_t xfer = dfu.functional().transfer_size;
  tu::DfuClient client(dfu, [](std::uint32_t ms) { std::this_thread::sleep_for(std::chrono::milliseconds(ms)); });
  ProgressBar bar(opt.has("quiet"));
  try {
    client.ensure_idle();
    std::uint16_t block = 0;
    for (std::size_t at = 0; at < bytes.size(); at += xfer, ++block) {
      const std::size_t n = std::min<std::size_t>(xfer, bytes.size() - at);
      client.download(block, std::span(bytes).subspan(at, n));
      bar({tu::FlashPhase::kWrite, at + n, bytes.size()});
    }
    client.manifest();
    std::vector<std::uint8_t> back, chunk(xfer);
    for (std::uint16_t b = 0;; ++b) {
      const std::size_t n = client.upload(b, chunk);
      back.insert(back.end(), chunk.begin(), chunk.begin() + static_cast<std::ptrdiff_t>(n));
      bar({tu::FlashPhase::kVerify, std::min(back.size(), bytes.size()), bytes.size()});
      if (n < xfer || back.size() > bytes.size()) break;
    }
    client.abort();
    if (back != bytes) {
      std::fprintf(stderr, "hadynet flash --model: the slot reads back %zu bytes that differ from the %zu sent: the "
                   "slot does not hold this model; flash it again\n", back.size(), bytes.size());
      return 6;
    }
  } catch (const tu::DfuError& e) {
    std::fprintf(stderr, "hadynet flash --model: %s; the slot holds no valid image (its header is written last), "
                 "the active model is unchanged\n", e.what());
    return 5;
  } catch (const tu::UsbTransferError& e) {
    std::fprintf(stderr, "hadynet flash --model: %s; the slot holds no valid image, the active model is unchanged\n",
                 e.what());
    return e.kind() == tu::UsbTransferError::Kind::kGone ? 4 : 7;
  }
  std::printf("model %s: %zu bytes (with the 16-byte envelope) in the inactive slot of hand %s, read back byte for "
              "byte\n", file.c_str(), bytes.size(), hand->serial.c_str());
  return 0;
}

}  // namespace

int run_flash(int argc, char** argv) {
  Options opt("flash",
              "Writes firmware into the forearm MCU over USB: a running hand is sent into the STM32 ROM DfuSe\n"
              "bootloader (DFU_DETACH; or use one already there: BOOT0 high + reset), only the sectors the\n"
              "image covers are erased, the image is written, read back and compared byte for byte, and the\n"
              "MCU starts it. FILE: the .elf (its load segments) or the .bin (at 0x08000000) of a build.\n"
              "--model FILE instead sends a model file (in a 16-byte envelope with its CRC-32) into the\n"
              "inactive model slot through the firmware's own DFU interface and reads it back.\n"
              "Exit status: 0 done, 1 no device / bad input, 2 usage, 3 image does not fit (nothing\n"
              "touched), 4 device vanished, 5 device reported an error, 6 verify mismatch, 7 other USB error.",
              "FIRMWARE.elf|.bin [--serial S] | --model FILE [--serial S]");
  opt.value("serial", "S", "the hand's serial number (hadynet devices), if several are attached");
  opt.value("model", "FILE", "send a model file into the inactive model slot instead of firmware");
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
  } catch (const std::exception& e) {
    std::fprintf(stderr, "\nhadynet flash: %s\n", error_text(e).c_str());
    return 1;
  }
}

}  // namespace hadynet::cli
