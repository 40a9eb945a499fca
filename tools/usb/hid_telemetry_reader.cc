#include "tools/usb/hid_telemetry_reader.h"

#include <hidapi.h>

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "firmware/usb/composite_descriptors.h"
#include "firmware/usb/usb_identity.h"

namespace hadynet::tools::usb {
namespace {

std::string narrow(const wchar_t* text) {
  std::string s;
  for (const wchar_t* p = text; p != nullptr && *p != 0; ++p) s.push_back(*p < 0x80 ? static_cast<char>(*p) : '?');
  return s;
}

struct Candidate {
  std::string path;
  std::string serial;
};

}  // namespace

HidTelemetryReader::HidTelemetryReader(const std::string& serial) {
  if (hid_init() != 0) throw std::runtime_error("hidapi cannot start (hid_init failed)");
  const auto& id = hadynet::usb::kHadynetUsbIdentity;
  std::vector<Candidate> hands;
  hid_device_info* list = hid_enumerate(id.vendor_id, id.product_id);
  for (const hid_device_info* d = list; d != nullptr; d = d->next) {
    if (d->interface_number != hadynet::usb::composite::kHidInterface) continue;
    hands.push_back({d->path, narrow(d->serial_number)});
  }
  hid_free_enumeration(list);
  char vid_pid[16];
  std::snprintf(vid_pid, sizeof vid_pid, "%04x:%04x", id.vendor_id, id.product_id);
  const std::string what = std::string("a HADYNET hand (") + vid_pid + ")";
  if (hands.empty()) {
    throw std::runtime_error("no telemetry interface of " + what +
                             " found; `hadynet devices` lists what is attached (and says if access is denied)");
  }
  const Candidate* chosen = nullptr;
  if (serial.empty()) {
    if (hands.size() > 1) {
      std::string serials;
      for (const auto& h : hands) serials += (serials.empty() ? "" : ", ") + h.serial;
      throw std::runtime_error(std::to_string(hands.size()) + " hands attached (" + serials +
                               "): choose one with --serial");
    }
    chosen = &hands[0];
  } else {
    for (const auto& h : hands) {
      if (h.serial == serial) chosen = &h;
    }
    if (chosen == nullptr) throw std::runtime_error("no hand with serial " + serial + " (see hadynet devices)");
  }
  device_ = hid_open_path(chosen->path.c_str());
  if (device_ == nullptr) {
    throw std::runtime_error("cannot open the telemetry interface of hand " + chosen->serial + " (" + chosen->path +
                             "): permission denied or busy; install udev/60-hadynet.rules (docs/usb.md)");
  }
  serial_ = chosen->serial;
}

HidTelemetryReader::~HidTelemetryReader() {
  if (device_ != nullptr) hid_close(device_);
  hid_exit();
}

std::size_t HidTelemetryReader::read(std::span<std::uint8_t> report, int timeout_ms) {
  const int n = hid_read_timeout(device_, report.data(), report.size(), timeout_ms);
  if (n < 0) {
    const wchar_t* error = hid_error(device_);
    throw std::runtime_error("telemetry read failed (device unplugged or reset?): " +
                             (error != nullptr ? narrow(error) : std::string("unknown error")));
  }
  return static_cast<std::size_t>(n);
}

}  // namespace hadynet::tools::usb
