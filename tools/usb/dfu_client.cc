#include "tools/usb/dfu_client.h"

#include <cstdio>

namespace hadynet::tools::usb {

namespace {

constexpr std::uint8_t kDfuseSetAddress = 0x21;
constexpr std::uint8_t kDfuseErase = 0x41;

std::string describe(const char* what, const DfuStatus& s) {
  char text[160];
  std::snprintf(text, sizeof text, "%s: the device reports %s (status 0x%02x) in state %s (%u)", what,
                status_name(s.status), static_cast<unsigned>(s.status), state_name(s.state),
                static_cast<unsigned>(s.state));
  return text;
}

}  // namespace

const char* state_name(dfu::State s) {
  switch (s) {
    case dfu::State::kAppIdle: return "appIDLE";
    case dfu::State::kAppDetach: return "appDETACH";
    case dfu::State::kIdle: return "dfuIDLE";
    case dfu::State::kDnloadSync: return "dfuDNLOAD-SYNC";
    case dfu::State::kDnBusy: return "dfuDNBUSY";
    case dfu::State::kDnloadIdle: return "dfuDNLOAD-IDLE";
    case dfu::State::kManifestSync: return "dfuMANIFEST-SYNC";
    case dfu::State::kManifest: return "dfuMANIFEST";
    case dfu::State::kManifestWaitReset: return "dfuMANIFEST-WAIT-RESET";
    case dfu::State::kUploadIdle: return "dfuUPLOAD-IDLE";
    case dfu::State::kError: return "dfuERROR";
  }
  return "an unknown state";
}

const char* status_name(dfu::Status s) {
  switch (s) {
    case dfu::Status::kOk: return "OK";
    case dfu::Status::kErrTarget: return "errTARGET (file not for this device)";
    case dfu::Status::kErrFile: return "errFILE (file failed verification)";
    case dfu::Status::kErrWrite: return "errWRITE (cannot write memory)";
    case dfu::Status::kErrErase: return "errERASE (memory erase failed)";
    case dfu::Status::kErrCheckErased: return "errCHECK_ERASED (erase check failed)";
    case dfu::Status::kErrProg: return "errPROG (program memory failed)";
    case dfu::Status::kErrVerify: return "errVERIFY (programmed memory failed verification)";
    case dfu::Status::kErrAddress: return "errADDRESS (address out of range)";
    case dfu::Status::kErrNotDone: return "errNOTDONE (download ended early)";
    case dfu::Status::kErrFirmware: return "errFIRMWARE (firmware corrupt)";
    case dfu::Status::kErrVendor: return "errVENDOR";
    case dfu::Status::kErrUsbReset: return "errUSBR (unexpected USB reset)";
    case dfu::Status::kErrPowerOnReset: return "errPOR (unexpected power-on reset)";
    case dfu::Status::kErrUnknown: return "errUNKNOWN";
    case dfu::Status::kErrStalledPacket: return "errSTALLEDPKT (request not expected in this state)";
  }
  return "an unknown status";
}

DfuStatus DfuClient::get_status() {
  std::uint8_t b[dfu::kStatusSize] = {};
  const std::size_t n = transport_.control_in(dfu::kGetStatus, 0, b);
  if (n != dfu::kStatusSize) {
    throw UsbTransferError(UsbTransferError::Kind::kOther,
                           "DFU_GETSTATUS returned " + std::to_string(n) + " bytes, expected 6");
  }
  DfuStatus s;
  s.status = static_cast<dfu::Status>(b[0]);
  s.poll_timeout_ms = static_cast<std::uint32_t>(b[1]) | (static_cast<std::uint32_t>(b[2]) << 8) |
                      (static_cast<std::uint32_t>(b[3]) << 16);
  s.state = static_cast<dfu::State>(b[4]);
  s.string_index = b[5];
  return s;
}

dfu::State DfuClient::get_state() {
  std::uint8_t b[1] = {};
  if (transport_.control_in(dfu::kGetState, 0, b) != 1) {
    throw UsbTransferError(UsbTransferError::Kind::kOther, "DFU_GETSTATE did not return 1 byte");
  }
  return static_cast<dfu::State>(b[0]);
}

void DfuClient::clear_status() { transport_.control_out(dfu::kClrStatus, 0, {}); }
void DfuClient::abort() { transport_.control_out(dfu::kAbort, 0, {}); }

void DfuClient::ensure_idle() {
  DfuStatus s = get_status();
  if (s.state == dfu::State::kError) {
    clear_status();
    s = get_status();
  }
  if (s.state == dfu::State::kDnloadIdle || s.state == dfu::State::kUploadIdle) {
    abort();
    s = get_status();
  }
  if (s.state != dfu::State::kIdle) throw DfuError(describe("cannot bring the device to dfuIDLE", s), s);
}

void DfuClient::wait_until_idle(const char* what) {
  std::uint64_t waited_ms = 0;
  for (;;) {
    const DfuStatus s = get_status();
    if (s.status != dfu::Status::kOk || s.state == dfu::State::kError) throw DfuError(describe(what, s), s);
    if (s.state == dfu::State::kDnloadIdle || s.state == dfu::State::kIdle) return;
    if (s.state != dfu::State::kDnBusy && s.state != dfu::State::kDnloadSync) {
      throw DfuError(describe(what, s), s);
    }
    if (waited_ms > busy_deadline_ms_) {
      throw DfuError(std::string(what) + ": the device stayed busy for more than " +
                         std::to_string(busy_deadline_ms_ / 1000) + " s",
                     s);
    }
    // At least 1 ms, so a device that reports 0 while busy is not polled flat out.
    const std::uint32_t ms = s.poll_timeout_ms > 0 ? s.poll_timeout_ms : 1;
    sleep_(ms);
    waited_ms += ms;
  }
}

void DfuClient::download(std::uint16_t block, std::span<const std::uint8_t> data) {
  transport_.control_out(dfu::kDnload, block, data);
  wait_until_idle(("block " + std::to_string(block)).c_str());
}

std::size_t DfuClient::upload(std::uint16_t block, std::span<std::uint8_t> buffer) {
  return transport_.control_in(dfu::kUpload, block, buffer);
}

void DfuClient::manifest() {
  transport_.control_out(dfu::kDnload, 0, {});
  std::uint64_t waited_ms = 0;
  for (;;) {
    const DfuStatus s = get_status();
    if (s.status != dfu::Status::kOk || s.state == dfu::State::kError) throw DfuError(describe("manifestation", s), s);
    if (s.state == dfu::State::kIdle) return;
    if (s.state != dfu::State::kManifestSync && s.state != dfu::State::kManifest) {
      throw DfuError(describe("manifestation", s), s);
    }
    if (waited_ms > busy_deadline_ms_) {
      throw DfuError("manifestation: the device stayed busy for more than " + std::to_string(busy_deadline_ms_ / 1000) +
                         " s",
                     s);
    }
    const std::uint32_t ms = s.poll_timeout_ms > 0 ? s.poll_timeout_ms : 1;
    sleep_(ms);
    waited_ms += ms;
  }
}

void DfuClient::finish_download() {
  transport_.control_out(dfu::kDnload, 0, {});
  try {
    const DfuStatus s = get_status();
    if (s.status != dfu::Status::kOk) throw DfuError(describe("leaving DFU", s), s);
  } catch (const UsbTransferError& e) {
    // The DfuSe bootloader starts the application at once and leaves the
    // bus; a vanished device or an unanswered status request is the normal end.
    if (e.kind() == UsbTransferError::Kind::kOther) throw;
  }
}

void DfuClient::dfuse_set_address(std::uint32_t address) {
  const std::uint8_t cmd[5] = {kDfuseSetAddress, static_cast<std::uint8_t>(address),
                               static_cast<std::uint8_t>(address >> 8), static_cast<std::uint8_t>(address >> 16),
                               static_cast<std::uint8_t>(address >> 24)};
  transport_.control_out(dfu::kDnload, 0, cmd);
  char what[48];
  std::snprintf(what, sizeof what, "set address 0x%08x", address);
  wait_until_idle(what);
}

void DfuClient::dfuse_erase_sector(std::uint32_t address) {
  const std::uint8_t cmd[5] = {kDfuseErase, static_cast<std::uint8_t>(address),
                               static_cast<std::uint8_t>(address >> 8), static_cast<std::uint8_t>(address >> 16),
                               static_cast<std::uint8_t>(address >> 24)};
  transport_.control_out(dfu::kDnload, 0, cmd);
  char what[48];
  std::snprintf(what, sizeof what, "erase of the sector at 0x%08x", address);
  wait_until_idle(what);
}

}  // namespace hadynet::tools::usb
