// The plain DFU 1.1 interface (DFU mode protocol, bInterfaceProtocol 2) that
// writes model images into flash regions (one region per alternate setting)
// through the flash seam. The whole DFU 1.1 state machine: dfuIDLE,
// dfuDNLOAD-SYNC, dfuDNBUSY, dfuDNLOAD-IDLE, dfuMANIFEST-SYNC, dfuMANIFEST,
// dfuUPLOAD-IDLE, dfuERROR with its status codes.
//
// Timing: a DNLOAD's data is only stored; the GETSTATUS that follows
// answers dfuDNBUSY with bwPollTimeout = the worst-case erase + program time,
// and service() (main loop) does the flash work, after which the state is
// dfuDNLOAD-SYNC and the next GETSTATUS answers dfuDNLOAD-IDLE. The final
// zero-length DNLOAD leads to dfuMANIFEST-SYNC; GETSTATUS answers dfuMANIFEST
// (state 7, never dfuMANIFEST-WAIT-RESET: manifestation tolerant), service()
// checks the image and programs its header, and the next GETSTATUS answers
// dfuIDLE. A GETSTATUS while service() has not run yet repeats dfuDNBUSY or
// dfuMANIFEST (a tolerance: DFU 1.1 lets the host wait bwPollTimeout).
//
// Images: the envelope of dfu_image.h; checks: magic/version (errFILE),
// header + payload larger than the region (errADDRESS, before anything is
// erased), more bytes than the header says (errADDRESS), fewer at the end
// (errNOTDONE), payload CRC of the received stream (errFILE), CRC of the
// flash read back (errVERIFY), flash errors (errERASE, errWRITE,
// errCHECK_ERASED, errPROG). Block numbers must count up by one from the
// first block's (errADDRESS). Any request not allowed in the current state
// STALLs and enters dfuERROR with errSTALLEDPKT (DFU 1.1 §6.1.2, A.2).
#ifndef HADYNET_FIRMWARE_USB_DFU_MODE_H_
#define HADYNET_FIRMWARE_USB_DFU_MODE_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/flash/flash_device.h"
#include "firmware/flash/flash_region_writer.h"
#include "firmware/usb/dfu_image.h"
#include "firmware/usb/dfu_spec.h"
#include "firmware/usb/usb_function.h"

namespace hadynet::usb {

// wTransferSize of the DFU-mode interface: bytes per DNLOAD/UPLOAD block.
inline constexpr std::uint16_t kDfuTransferSize = 256;
static_assert(kDfuTransferSize <= kControlBufferSize, "a DFU block must fit the control buffer");
// bwPollTimeout answered while the image is checked and its header written, ms.
inline constexpr std::uint32_t kDfuManifestPollMs = 100;

struct DfuTarget {
  flash::FlashRegion region{};  // sector-aligned (else every DNLOAD/UPLOAD is refused: errTARGET)
  bool can_download = false;
  bool can_upload = false;
};

class DfuMode final : public UsbFunction {
 public:
  DfuMode(flash::FlashDevice& flash, std::span<const DfuTarget> targets, std::uint8_t interface) noexcept
      : flash_(flash), targets_(targets), interface_(interface) {}

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
  std::uint32_t images_written() const noexcept { return images_written_; }
  // bwPollTimeout of the last GETSTATUS reply, ms.
  std::uint32_t last_poll_timeout_ms() const noexcept { return poll_ms_; }

 private:
  ControlReply refuse() noexcept;  // STALL + dfuERROR(errSTALLEDPKT)
  void fail(dfu::Status status) noexcept;
  void reset_to_idle() noexcept;
  ControlReply get_status(std::span<std::uint8_t> buffer) noexcept;
  ControlReply upload(const SetupPacket& s, std::span<std::uint8_t> buffer) noexcept;
  void process_block() noexcept;
  void manifest() noexcept;
  static dfu::Status to_dfu_status(const flash::WriteResult& r) noexcept;
  bool target_usable() const noexcept;

  flash::FlashDevice& flash_;
  std::span<const DfuTarget> targets_;
  std::uint8_t interface_;
  std::uint8_t alternate_ = 0;

  dfu::State state_ = dfu::State::kIdle;
  dfu::Status status_ = dfu::Status::kOk;
  std::uint32_t poll_ms_ = 0;

  // Download.
  flash::FlashRegionWriter writer_{};
  std::uint8_t block_[kDfuTransferSize] = {};
  std::size_t block_size_ = 0;
  bool block_pending_ = false;     // stored by DNLOAD, not yet written
  bool manifest_pending_ = false;  // final DNLOAD seen, image not yet checked
  std::uint16_t next_block_ = 0;
  std::uint8_t header_bytes_[kDfuImageHeaderSize] = {};
  DfuImageHeader header_{};
  std::uint32_t received_ = 0;  // bytes of the file so far (header included)
  std::uint32_t stream_crc_ = 0;

  // Upload.
  std::uint32_t upload_offset_ = 0;
  std::uint32_t upload_size_ = 0;
  std::uint16_t upload_next_block_ = 0;

  std::uint32_t images_written_ = 0;
};

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_DFU_MODE_H_
