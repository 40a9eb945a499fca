#include "test/dfuse_sim/dfuse_rom_interface.h"

namespace hadynet::usb::host_testing {

namespace {

constexpr std::uint8_t kCmdGet = 0x00;
constexpr std::uint8_t kCmdSetAddress = 0x21;
constexpr std::uint8_t kCmdErase = 0x41;
constexpr std::uint8_t kCmdReadUnprotect = 0x92;
constexpr std::uint32_t kCommandPollMs = 1;   // set address, leave
constexpr std::uint32_t kProgramUsPerByte = flash::stm32f405::kProgramMaxUsPerByte;

// The flash address of DfuSe block `block` (>= 2); 64 bits: no wrap-around.
std::uint64_t block_address(std::uint32_t pointer, std::uint16_t block) noexcept {
  return pointer + static_cast<std::uint64_t>(block - 2) * kDfuseTransferSize;
}

bool in_flash(std::uint64_t address, std::size_t n) noexcept {
  return address <= 0xFFFFFFFFull && RomFlashModel::contains(static_cast<std::uint32_t>(address), n);
}

}  // namespace

bool DfuseRomInterface::configure(DeviceController& controller) noexcept {
  controller_ = &controller;
  return true;
}

void DfuseRomInterface::deconfigure() noexcept {
  // SET_CONFIGURATION or a bus reset: back to dfuIDLE, anything stored dropped.
  state_ = dfu::State::kIdle;
  status_ = dfu::Status::kOk;
  pending_ = Pending::kNone;
  leave_after_status_ = false;
  vanish_after_status_ = false;
}

bool DfuseRomInterface::set_alternate(std::uint8_t interface, std::uint8_t alternate) noexcept {
  if (interface != interface_ || alternate >= kDfuseAlternates) return false;
  alternate_ = alternate;
  return true;
}

ControlReply DfuseRomInterface::refuse() noexcept {
  state_ = dfu::State::kError;
  status_ = dfu::Status::kErrStalledPacket;
  pending_ = Pending::kNone;
  return ControlReply::stall();
}

ControlReply DfuseRomInterface::control_setup(const SetupPacket& s, std::span<std::uint8_t> buffer) noexcept {
  if (s.kind() != RequestKind::kClass || s.recipient() != Recipient::kInterface || s.index != interface_) {
    return ControlReply::stall();  // e.g. a standard GET_DESCRIPTOR to the interface: none here
  }
  if (faults_.stall_request && *faults_.stall_request == s.request && ++stall_seen_ == faults_.stall_occurrence) {
    return refuse();
  }
  // dfuDNBUSY and dfuMANIFEST answer GETSTATUS only (DFU 1.1 A.2).
  const bool busy = state_ == dfu::State::kDnBusy || state_ == dfu::State::kManifest;
  switch (s.request) {
    case dfu::kDnload:
      if (s.is_in() || busy) return refuse();
      return dnload(s);
    case dfu::kUpload:
      if (!s.is_in() || busy) return refuse();
      return upload(s, buffer);
    case dfu::kGetStatus:
      if (!s.is_in() || s.value != 0 || s.length != dfu::kStatusSize) return refuse();
      return get_status(buffer);
    case dfu::kGetState:
      if (!s.is_in() || s.value != 0 || s.length != 1 || busy) return refuse();
      buffer[0] = static_cast<std::uint8_t>(state_);
      return ControlReply::data_in(1);
    case dfu::kClrStatus:
      if (s.is_in() || s.length != 0 || state_ != dfu::State::kError) return refuse();
      state_ = dfu::State::kIdle;
      status_ = dfu::Status::kOk;
      return ControlReply::ack();
    case dfu::kAbort:
      if (s.is_in() || s.length != 0 || busy || state_ == dfu::State::kError) return refuse();
      state_ = dfu::State::kIdle;
      pending_ = Pending::kNone;
      return ControlReply::ack();
    case dfu::kDetach:
      return refuse();  // a runtime request: not valid in DFU mode
    default:
      return ControlReply::stall();  // unknown bRequest: the stack's normal STALL, state unchanged
  }
}

ControlReply DfuseRomInterface::dnload(const SetupPacket& s) noexcept {
  if (state_ != dfu::State::kIdle && state_ != dfu::State::kDnloadIdle) return refuse();
  if (s.length == 0) {  // DfuSe leave
    pending_ = Pending::kLeave;
    state_ = dfu::State::kManifestSync;
    return ControlReply::ack();
  }
  if (s.length > kDfuseTransferSize || s.value == 1) return refuse();  // block 1 is not used by DfuSe
  return ControlReply::data_out();
}

bool DfuseRomInterface::control_out(const SetupPacket& s, std::span<const std::uint8_t> data) noexcept {
  if (s.request != dfu::kDnload || data.size() > block_.size()) return false;
  for (std::size_t i = 0; i < data.size(); ++i) block_[i] = data[i];
  block_size_ = data.size();
  block_number_ = s.value;
  pending_ = s.value == 0 ? Pending::kCommand : Pending::kWrite;
  state_ = dfu::State::kDnloadSync;
  ++downloads_;
  return true;
}

ControlReply DfuseRomInterface::upload(const SetupPacket& s, std::span<std::uint8_t> buffer) noexcept {
  if (state_ != dfu::State::kIdle && state_ != dfu::State::kUploadIdle) return refuse();
  if (s.value == 0) {
    const std::uint8_t commands[] = {kCmdGet, kCmdSetAddress, kCmdErase, kCmdReadUnprotect};
    for (std::size_t i = 0; i < sizeof commands && i < buffer.size(); ++i) buffer[i] = commands[i];
    state_ = dfu::State::kUploadIdle;
    return ControlReply::data_in(sizeof commands);
  }
  if (s.value == 1 || s.length > kDfuseTransferSize || s.length > buffer.size()) return refuse();
  const std::uint64_t address = block_address(pointer_, s.value);
  if (alternate_ != 0 || !in_flash(address, s.length)) {
    state_ = dfu::State::kError;
    status_ = dfu::Status::kErrAddress;
    return ControlReply::stall();
  }
  flash_.read(static_cast<std::uint32_t>(address), buffer.first(s.length));
  state_ = dfu::State::kUploadIdle;
  return ControlReply::data_in(s.length);
}

ControlReply DfuseRomInterface::get_status(std::span<std::uint8_t> buffer) noexcept {
  switch (state_) {
    case dfu::State::kDnloadSync:  // run what the DNLOAD stored; report busy
      result_ = pending_ == Pending::kCommand ? run_command() : run_write();
      datasheet_poll_ms_ += poll_ms_;
      pending_ = Pending::kNone;
      state_ = dfu::State::kDnBusy;
      break;
    case dfu::State::kDnBusy:  // the operation is done: its outcome
      poll_ms_ = 0;
      if (result_ == dfu::Status::kOk) {
        state_ = dfu::State::kDnloadIdle;
      } else {
        state_ = dfu::State::kError;
        status_ = result_;
      }
      break;
    case dfu::State::kManifestSync:  // leave: answered, then off the bus
      poll_ms_ = kCommandPollMs;
      state_ = dfu::State::kManifest;
      pending_ = Pending::kNone;
      leave_after_status_ = true;
      break;
    default:
      poll_ms_ = 0;
      break;
  }
  // 64 bits: a mass erase (~41 s) times a large percent does not wrap.
  const std::uint64_t scaled = (static_cast<std::uint64_t>(poll_ms_) * poll_percent_ + 99) / 100;
  const std::uint32_t reported = static_cast<std::uint32_t>(scaled > 0xFFFFFF ? 0xFFFFFF : scaled);  // 24 bits
  buffer[0] = static_cast<std::uint8_t>(status_);
  buffer[1] = static_cast<std::uint8_t>(reported);
  buffer[2] = static_cast<std::uint8_t>(reported >> 8);
  buffer[3] = static_cast<std::uint8_t>(reported >> 16);
  buffer[4] = static_cast<std::uint8_t>(state_);
  buffer[5] = 0;  // iString
  return ControlReply::data_in(dfu::kStatusSize);
}

dfu::Status DfuseRomInterface::run_command() noexcept {
  poll_ms_ = kCommandPollMs;
  const std::uint8_t command = block_[0];
  if (command == kCmdErase && block_size_ == 1) {  // mass erase
    ++erase_commands_;
    if (alternate_ != 0) return dfu::Status::kErrTarget;
    poll_ms_ = 0;
    for (std::size_t i = 0; i < RomFlashModel::sector_count(); ++i) {
      flash_.erase_sector(i);
      poll_ms_ += RomFlashModel::sector(i).erase_max_ms;
    }
    return dfu::Status::kOk;
  }
  if (block_size_ != 5 || (command != kCmdSetAddress && command != kCmdErase)) {
    return dfu::Status::kErrUnknown;  // 0x92 (not modelled), other commands, wrong lengths
  }
  const std::uint32_t address = get_le32(block_.data() + 1);
  const std::optional<std::size_t> sector = RomFlashModel::sector_at(address);
  if (command == kCmdSetAddress) {
    if (alternate_ != 0 || !sector) return dfu::Status::kErrTarget;
    pointer_ = address;
    return dfu::Status::kOk;
  }
  ++erase_commands_;
  if (alternate_ != 0 || !sector) return dfu::Status::kErrTarget;
  flash_.erase_sector(*sector);
  poll_ms_ = RomFlashModel::sector(*sector).erase_max_ms;
  return dfu::Status::kOk;
}

dfu::Status DfuseRomInterface::run_write() noexcept {
  poll_ms_ = static_cast<std::uint32_t>((block_size_ * kProgramUsPerByte + 999) / 1000);
  if (faults_.error_at_block != 0 && block_number_ == faults_.error_at_block) return faults_.error_status;
  const std::uint64_t address = block_address(pointer_, block_number_);
  if (alternate_ != 0 || !in_flash(address, block_size_)) return dfu::Status::kErrAddress;
  const bool exact =
      flash_.program(static_cast<std::uint32_t>(address), std::span<const std::uint8_t>(block_.data(), block_size_));
  if (faults_.vanish_after_block != 0 && block_number_ == faults_.vanish_after_block) vanish_after_status_ = true;
  return exact ? dfu::Status::kOk : dfu::Status::kErrVerify;
}

void DfuseRomInterface::control_complete(const SetupPacket& s) noexcept {
  if (s.request != dfu::kGetStatus) return;
  if (leave_after_status_) {
    jump_address_ = pointer_;
    leave_bus();
  } else if (vanish_after_status_) {
    leave_bus();
  }
}

void DfuseRomInterface::leave_bus() noexcept {
  leave_after_status_ = false;
  vanish_after_status_ = false;
  left_ = true;
  if (controller_ != nullptr) controller_->set_connected(false);  // the pull-up goes with the jump / power
}

}  // namespace hadynet::usb::host_testing
