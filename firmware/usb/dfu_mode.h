// The plain DFU 1.1 interface (DFU mode protocol, bInterfaceProtocol 2)
// that carries signed model images (firmware/model_update/model_image.h:
// a 256-byte header, then the payload) into the device's model slots
// through ModelSlots (firmware/model_update/model_slots.h), and reads slots
// back as image files (slot_image_file.h). The whole DFU 1.1 state machine:
// dfuIDLE, dfuDNLOAD-SYNC, dfuDNBUSY, dfuDNLOAD-IDLE, dfuMANIFEST-SYNC,
// dfuMANIFEST, dfuUPLOAD-IDLE, dfuERROR with its status codes.
//
// Alternates:
//   alt 0 "model update": DNLOAD streams an image into the slot ModelSlots
//          picks (never the slot in use); UPLOAD reads back the slot the
//          last accepted update of this power-on wrote, before any update
//          the slot the next update would write.
//   alt 1 "running model", read only: UPLOAD reads the slot the boot rule
//          chose (0 bytes while the factory model runs); DNLOAD: errWRITE.
//
// Download: the file's first 256 bytes go to begin_update() (which checks
// everything the header shows, signature included, before anything is
// erased, and picks the target), later bytes to append_update(), the final
// zero-length DNLOAD to finish_update() (length, stream hash, read-back,
// header programmed last). A refusal at any point leaves the slot in use
// and the boot choice untouched (ModelSlots' rules).
//
// Timing: a DNLOAD's data is only stored; the GETSTATUS that follows
// answers dfuDNBUSY with bwPollTimeout = that block's worst-case work
// (dfu_update_timing.h), and service() (main loop) does it, after which the
// next GETSTATUS answers dfuDNLOAD-IDLE. The zero-length DNLOAD leads to
// dfuMANIFEST-SYNC; GETSTATUS answers dfuMANIFEST (state 7, never
// dfuMANIFEST-WAIT-RESET: manifestation tolerant) with kDfuManifestMs,
// service() runs finish_update(), and the next GETSTATUS answers dfuIDLE. A
// GETSTATUS while service() has not run yet repeats dfuDNBUSY or
// dfuMANIFEST (DFU 1.1 lets the host wait bwPollTimeout).
//
// Errors: dfuERROR with the status of dfu_update_status.h for a refusal by
// ModelSlots, errADDRESS for a block number out of sequence, errNOTDONE for a
// file that ends inside the header, errWRITE for DNLOAD on alt 1, errTARGET
// for DNLOAD/UPLOAD on a device without model slots, errUNKNOWN for a flash
// read error during UPLOAD. Any request not allowed in the current state
// STALLs and enters dfuERROR with errSTALLEDPKT (DFU 1.1 §6.1.2, A.2).
// Every error also sets a description (status_text(): "signed by another
// key", ...), which GETSTATUS names in iString while it is not empty; a
// finished download sets one too ("image sequence N written to slot B:
// ..."). It is cleared when a download starts and on every return to
// dfuIDLE by CLRSTATUS, ABORT, SET_INTERFACE or a bus reset.
// Entering dfuERROR or dfuIDLE in the middle of a download ends the update
// (ModelSlots::abort_update(): the target keeps no header).
#ifndef HADYNET_FIRMWARE_USB_DFU_MODE_H_
#define HADYNET_FIRMWARE_USB_DFU_MODE_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/flash/flash_device.h"
#include "firmware/model_update/model_image.h"
#include "firmware/model_update/model_slots.h"
#include "firmware/usb/dfu_spec.h"
#include "firmware/usb/dfu_update_status.h"
#include "firmware/usb/usb_function.h"

namespace hadynet::usb {

// wTransferSize of the DFU-mode interface: bytes per DNLOAD/UPLOAD block.
inline constexpr std::uint16_t kDfuTransferSize = 256;
static_assert(kDfuTransferSize <= kControlBufferSize, "a DFU block must fit the control buffer");

inline constexpr std::uint8_t kDfuAltModelUpdate = 0;
inline constexpr std::uint8_t kDfuAltRunningModel = 1;
inline constexpr std::uint8_t kDfuAlternateCount = 2;

// The model slots behind the interface: ModelSlots (updates, the boot
// choice) and the flash it was built over (UPLOAD reads the slots through
// it; poll times come from its sector table). Both null: a device without
// model flash, which refuses every DNLOAD and UPLOAD with errTARGET.
struct ModelSlotsAccess {
  model_update::ModelSlots* slots = nullptr;
  const flash::FlashDevice* flash = nullptr;
};

class DfuMode final : public UsbFunction {
 public:
  // `status_string`: the string descriptor index that serves status_text().
  DfuMode(const ModelSlotsAccess& model, std::uint8_t interface, std::uint8_t status_string) noexcept;

  bool owns_interface(std::uint8_t interface) const noexcept override { return interface == interface_; }
  bool owns_endpoint(EndpointAddress) const noexcept override { return false; }
  ControlReply control_setup(const SetupPacket& s, std::span<std::uint8_t> buffer) noexcept override;
  bool control_out(const SetupPacket& s, std::span<const std::uint8_t> data) noexcept override;
  bool configure(DeviceController& controller) noexcept override;
  void deconfigure() noexcept override;
  bool set_alternate(std::uint8_t interface, std::uint8_t alternate) noexcept override;
  std::uint8_t alternate(std::uint8_t interface) const noexcept override;
  void service() noexcept override;

  dfu::State state() const noexcept { return state_; }
  dfu::Status status() const noexcept { return status_; }
  // Images ModelSlots accepted whole (finish_update() returned kOk).
  std::uint32_t images_written() const noexcept { return images_written_; }
  // bwPollTimeout of the last GETSTATUS reply, ms.
  std::uint32_t last_poll_timeout_ms() const noexcept { return poll_ms_; }
  // The description of the current error or of the last finished download
  // ("" if none); stable storage (the string table points at it).
  const char* status_text() const noexcept { return text_.c_str(); }
  // The UpdateError behind the current error (kOk for DFU-level errors).
  model_update::UpdateError update_error() const noexcept { return update_error_; }

 private:
  ControlReply refuse() noexcept;  // STALL + dfuERROR(errSTALLEDPKT)
  void fail(dfu::Status status, const char* text) noexcept;
  void fail_update(model_update::UpdateError error, bool in_erase) noexcept;
  void end_update() noexcept;
  void reset_to_idle() noexcept;
  ControlReply start_download(const SetupPacket& s) noexcept;
  ControlReply get_status(std::span<std::uint8_t> buffer) noexcept;
  ControlReply upload(const SetupPacket& s, std::span<std::uint8_t> buffer) noexcept;
  bool start_upload() noexcept;
  bool upload_slot(flash::FlashRegion& region) const noexcept;
  std::uint32_t block_work_ms() const noexcept;
  void process_block() noexcept;
  bool append(std::span<const std::uint8_t> payload) noexcept;
  void manifest() noexcept;
  std::uint32_t header_sequence() const noexcept;

  model_update::ModelSlots* slots_;
  const flash::FlashDevice* flash_;
  std::uint8_t interface_;
  std::uint8_t status_string_;
  std::uint8_t alternate_ = kDfuAltModelUpdate;

  dfu::State state_ = dfu::State::kIdle;
  dfu::Status status_ = dfu::Status::kOk;
  model_update::UpdateError update_error_ = model_update::UpdateError::kOk;
  std::uint32_t poll_ms_ = 0;
  DfuStatusText text_;

  // Download.
  std::uint8_t block_[kDfuTransferSize] = {};
  std::size_t block_size_ = 0;
  bool block_pending_ = false;     // stored by DNLOAD, not yet processed
  bool manifest_pending_ = false;  // final DNLOAD seen, finish_update() not yet run
  std::uint16_t next_block_ = 0;
  std::uint8_t header_[model_update::kImageHeaderSize] = {};
  std::size_t header_received_ = 0;  // bytes of header_ filled (begin_update() runs at 256)
  // The slot the last accepted update (begin_update() kOk) of this power-on wrote.
  bool wrote_a_slot_ = false;
  model_update::SlotId written_slot_ = model_update::SlotId::kA;

  // Upload.
  flash::FlashRegion upload_region_{};
  std::uint32_t upload_offset_ = 0;
  std::uint32_t upload_size_ = 0;
  std::uint16_t upload_next_block_ = 0;

  std::uint32_t images_written_ = 0;
};

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_DFU_MODE_H_
