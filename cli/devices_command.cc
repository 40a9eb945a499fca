// hadynet devices: every HADYNET forearm MCU on USB (serial number, firmware
// version, the model it runs: hash and source, the interfaces it offers)
// and every STM32 waiting in its ROM DfuSe bootloader
// (tools/usb/usb_inventory.h).
#include <libusb.h>

#include <cstdio>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/options.h"
#include "firmware/usb/usb_identity.h"
#include "tools/usb/usb_inventory.h"

namespace hadynet::cli {
namespace {

using tools::usb::AttachedDevice;

std::string interfaces_text(const tools::usb::InterfacesPresent& p) {
  std::string s;
  const auto add = [&](bool present, const char* name) {
    if (!present) return;
    if (!s.empty()) s += ",";
    s += name;
  };
  add(p.cdc_acm, "link(cdc-acm)");
  add(p.hid, "telemetry(hid)");
  add(p.dfu_runtime, "dfu-runtime");
  add(p.dfu_mode, "dfu-model");
  return s.empty() ? "none" : s;
}

void print_device(const AttachedDevice& d) {
  const bool hand = d.kind == AttachedDevice::Kind::kHand;
  std::printf("%s  bus %03u device %03u  port %s  %04x:%04x", hand ? "hand      " : "bootloader", d.bus, d.address,
              d.port_path.c_str(), d.vendor_id, d.product_id);
  if (d.access_denied) {
    std::printf("  (permission denied: install udev/60-hadynet.rules, see docs/usb.md)\n");
    return;
  }
  std::printf("  serial %s", d.serial.empty() ? "?" : d.serial.c_str());
  if (hand) {
    // The running model: its hash and where it comes from (factory / slot, sequence).
    const std::string source = d.model_source.empty() ? std::string() : " (" + d.model_source + ")";
    std::printf("  firmware %s  model %s%s  interfaces %s",
                d.firmware_version.empty() ? "?" : d.firmware_version.c_str(),
                d.model_hash.empty() ? "?" : d.model_hash.c_str(), source.c_str(), interfaces_text(d.interfaces).c_str());
  } else {
    std::printf("  (STM32 ROM DfuSe bootloader: `hadynet flash` writes firmware through it)");
  }
  if (!d.read_error.empty()) std::printf("  [%s]", d.read_error.c_str());
  std::printf("\n");
}

struct ContextCloser {
  void operator()(libusb_context* c) const { libusb_exit(c); }
};

}  // namespace

int run_devices(int argc, char** argv) {
  Options opt("devices",
              "Lists every HADYNET forearm MCU on USB (the firmware's VID:PID, firmware/usb/usb_identity.h):\n"
              "bus, device and port, serial number (the MCU's unique ID), firmware version, the model it runs\n"
              "(its hash, and where it comes from: \"factory\", the compiled-in model, or \"slot A|B,\n"
              "sequence N\", a signed model image the boot rule chose) and the interfaces it offers; and every\n"
              "STM32 in its ROM DfuSe bootloader (0483:df11).\n"
              "Exit status: 0 if at least one device was listed, 1 if none was found or none could be\n"
              "opened (permission: udev/60-hadynet.rules, docs/usb.md), 2 on a usage error.",
              "");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (!opt.positional().empty()) {
    std::fprintf(stderr, "hadynet devices: takes no arguments (see --help)\n");
    return 2;
  }
  libusb_context* raw = nullptr;
  if (const int r = libusb_init(&raw); r != LIBUSB_SUCCESS) {
    std::fprintf(stderr, "hadynet devices: libusb cannot start: %s\n", libusb_strerror(r));
    return 1;
  }
  const std::unique_ptr<libusb_context, ContextCloser> context(raw);
  try {
    const auto devices = tools::usb::list_attached_devices(context.get());
    if (devices.empty()) {
      std::fprintf(stderr,
                   "hadynet devices: no HADYNET device (%04x:%04x) and no STM32 bootloader (%04x:%04x) on USB; is the "
                   "cable a data cable, and the board powered?\n",
                   hadynet::usb::kHadynetUsbIdentity.vendor_id, hadynet::usb::kHadynetUsbIdentity.product_id,
                   tools::usb::kStmVendorId, tools::usb::kStmDfuProductId);
      return 1;
    }
    int usable = 0;
    for (const auto& d : devices) {
      print_device(d);
      if (!d.access_denied) ++usable;
    }
    if (usable == 0) {
      std::fprintf(stderr,
                   "hadynet devices: found %zu device(s) but may not open any: install the udev rules "
                   "(sudo cp udev/60-hadynet.rules /etc/udev/rules.d/ && sudo udevadm control --reload && sudo "
                   "udevadm trigger), then re-plug\n",
                   devices.size());
      return 1;
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hadynet devices: %s\n", error_text(e).c_str());
    return 1;
  }
}

}  // namespace hadynet::cli
