// The device core above the seam: the EP0 control state machine (SETUP,
// DATA IN, DATA OUT, STATUS, zero-length packets, STALL), the device states
// of USB 2.0 §9.1 (default, addressed, configured), the standard requests,
// endpoint halts, and routing to the functions (usb_function.h).
//
// One configuration (value 1). Descriptors are data given at construction;
// strings are ASCII, sent as UTF-16LE. Allocation-free; errors are STALLs.
#ifndef HADYNET_FIRMWARE_USB_USB_DEVICE_H_
#define HADYNET_FIRMWARE_USB_USB_DEVICE_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/usb/device_controller.h"
#include "firmware/usb/usb_function.h"
#include "firmware/usb/usb_spec.h"

namespace hadynet::usb {

inline constexpr std::uint16_t kLangIdEnglishUs = 0x0409;
inline constexpr std::size_t kMaxStringChars = 126;  // (255 - 2) / 2 UTF-16 units

struct DescriptorSet {
  std::span<const std::uint8_t> device;          // 18 bytes
  std::span<const std::uint8_t> configuration;   // the whole set, wTotalLength bytes
  std::span<const char* const> strings;          // index k >= 1: ASCII text; [0] unused (LANGID)
};

enum class DeviceState : std::uint8_t { kDefault, kAddressed, kConfigured };
enum class ControlStage : std::uint8_t { kIdle, kDataIn, kDataOut, kStatusIn, kStatusOut, kStalled };

class UsbDevice final : public ControllerEventHandler {
 public:
  UsbDevice(DeviceController& controller, const DescriptorSet& descriptors,
            std::span<UsbFunction* const> functions, bool self_powered) noexcept
      : controller_(controller), descriptors_(descriptors), functions_(functions), self_powered_(self_powered) {}

  // Brings the controller up and connects (pull-up on).
  void start() noexcept;
  void handle(const ControllerEvent& event) noexcept override;
  // Main-loop work of every function.
  void service() noexcept;

  DeviceState state() const noexcept { return state_; }
  ControlStage control_stage() const noexcept { return stage_; }
  std::uint8_t address() const noexcept { return address_; }
  std::uint8_t configuration() const noexcept { return state_ == DeviceState::kConfigured ? 1 : 0; }
  bool suspended() const noexcept { return suspended_; }
  bool endpoint_halted(EndpointAddress ep) const noexcept;

 private:
  void bus_reset() noexcept;
  void setup(const SetupPacket& s) noexcept;
  void ep0_in_complete(std::size_t bytes) noexcept;
  void ep0_out_complete(std::size_t bytes) noexcept;
  void stall() noexcept;
  void send_in_packet() noexcept;
  void start_status_in() noexcept;
  void start_status_out() noexcept;
  void status_complete() noexcept;
  void arm_data_out() noexcept;
  void accept(const ControlReply& reply) noexcept;

  ControlReply standard_device(const SetupPacket& s) noexcept;
  ControlReply standard_interface(const SetupPacket& s) noexcept;
  ControlReply standard_endpoint(const SetupPacket& s) noexcept;
  ControlReply get_descriptor(const SetupPacket& s) noexcept;
  std::size_t string_descriptor(std::uint8_t index) noexcept;
  bool set_configuration(std::uint16_t value) noexcept;
  void deconfigure() noexcept;
  UsbFunction* function_for_interface(std::uint8_t interface) const noexcept;
  UsbFunction* function_for_endpoint(EndpointAddress ep) const noexcept;
  bool endpoint_exists(EndpointAddress ep) const noexcept;
  static std::size_t halt_index(EndpointAddress ep) noexcept;

  DeviceController& controller_;
  DescriptorSet descriptors_;
  std::span<UsbFunction* const> functions_;
  bool self_powered_ = false;

  DeviceState state_ = DeviceState::kDefault;
  std::uint8_t address_ = 0;
  std::uint8_t pending_address_ = 0;
  bool address_pending_ = false;
  bool suspended_ = false;
  bool halted_[2 * (kMaxEndpointNumber + 1)] = {};

  // The control transfer in progress.
  ControlStage stage_ = ControlStage::kIdle;
  SetupPacket setup_{};
  UsbFunction* owner_ = nullptr;      // the function that accepted it (nullptr: the core)
  std::size_t data_size_ = 0;          // bytes of the data stage (IN: min(reply, wLength))
  std::size_t data_done_ = 0;          // bytes moved so far
  std::size_t last_packet_ = 0;        // size of the last IN packet started
  std::uint8_t buffer_[kControlBufferSize] = {};
  std::uint8_t status_buffer_[kEp0MaxPacket] = {};  // the OUT status stage's packet lands here
};

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_USB_DEVICE_H_
