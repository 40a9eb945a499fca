// Test fixture for the USB stack: the composite device over the host backend
// (FakeController), with the real link device end (DeviceLink + q15
// runtime), a simulated NOR flash laid out like the STM32F405's 1 MiB with
// its two model slots managed by a ModelSlots (booted before the device is
// built, as the firmware does), and a detach hook that records. A reboot is
// a new device over the same flash cells. Helpers build SETUP packets and
// run control transfers.
#ifndef HADYNET_TEST_USB_USB_TEST_DEVICE_H_
#define HADYNET_TEST_USB_USB_TEST_DEVICE_H_

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/flash/simulated_nor_flash.h"
#include "firmware/flash/stm32f405_flash_layout.h"
#include "firmware/link/device_link.h"
#include "firmware/link/frame.h"
#include "firmware/model_update/model_slots.h"
#include "firmware/usb/hadynet_usb_device.h"
#include "firmware/usb/host/fake_controller.h"
#include "hadynet_model_q15.h"
#include "test/usb/usb_test_images.h"

namespace hadynet::usb::testing {

using Q = model_q15::Model;
using host::ControlResult;
using host::FakeController;
using host::Handshake;

struct RecordingDetachHook final : DetachHook {
  void detach_to_bootloader(std::uint16_t timeout_ms) noexcept override {
    ++calls;
    last_timeout_ms = timeout_ms;
  }
  int calls = 0;
  std::uint16_t last_timeout_ms = 0;
};

// The boot's self-test with a fixed verdict (the app's own self-test is
// exercised by firmware_usb_test.cc and test/usb_host/ with real images).
struct VerdictSelfTest final : model_update::SelfTest {
  explicit VerdictSelfTest(bool verdict) : pass(verdict) {}
  bool run(std::span<const std::uint8_t>, const model_update::ModelImageHeader&) noexcept override {
    ++runs;
    return pass;
  }
  bool pass;
  int runs = 0;
};

// A fixed unique ID (bytes as the board reads them) and its serial string.
inline constexpr std::array<std::uint8_t, kUniqueIdBytes> kTestUid = {0x33, 0x00, 0x2A, 0x00, 0x0E, 0x47,
                                                                      0x37, 0x36, 0x34, 0x32, 0x38, 0x39};
inline constexpr const char* kTestUidHex = "33002A000E47373634323839";
inline constexpr const char* kTestFirmwareVersion = "0.1.0";

inline constexpr flash::FlashRegion kSlotA{flash::stm32f405::kModelSlotAOffset, flash::stm32f405::kModelSlotSize};
inline constexpr flash::FlashRegion kSlotB{flash::stm32f405::kModelSlotBOffset, flash::stm32f405::kModelSlotSize};

using Usb = HadynetUsbDevice<Q, link::DeviceLink<Q>, link::kMaxWireFrame>;

struct DeviceSetup {
  model_update::ModelIdentity identity = firmware_identity();
  bool model_slots = true;         // false: a board without model flash (no ModelSlots)
  bool boot = true;                // run the boot rule before the USB device is built
  bool self_test_passes = true;    // the boot's self-test verdict
  const Bytes* cells = nullptr;    // the flash's contents at power-on (a reboot); null: erased
};

struct UsbTestDevice {
  explicit UsbTestDevice(const DeviceSetup& setup = {})
      : storage(flash::stm32f405::kFlashSize),
        flash(flash::stm32f405::kSectors, storage),
        runtime(std::make_unique<firmware::HadynetRuntime<Q>>()),
        link(std::make_unique<link::DeviceLink<Q>>(*runtime)),
        self_test(setup.self_test_passes) {
    if (setup.cells != nullptr) std::copy(setup.cells->begin(), setup.cells->end(), storage.begin());
    if (setup.model_slots) {
      slots = std::make_unique<model_update::ModelSlots>(flash, kSlotA, kSlotB, setup.identity,
                                                         device_key().public_key, flash.contents());
      if (setup.boot) slots->boot(self_test);
    }
    usb = std::make_unique<Usb>(controller, *link, ModelSlotsAccess{slots.get(), slots ? &flash : nullptr}, hook,
                                kTestUid, kTestFirmwareVersion);
    usb->start();
  }

  // A power-on reset: a new device over a copy of this one's cells.
  std::unique_ptr<UsbTestDevice> reboot(DeviceSetup setup = {}) const {
    const Bytes cells(flash.contents().begin(), flash.contents().end());
    setup.cells = &cells;
    return std::make_unique<UsbTestDevice>(setup);
  }

  // Bus reset, SET_ADDRESS(5), SET_CONFIGURATION(1); expects success.
  void enumerate() {
    controller.bus_reset();
    ASSERT_TRUE(controller.control(setup_out_device(request::kSetAddress, 5), {}, {}).ok());
    ASSERT_TRUE(controller.control(setup_out_device(request::kSetConfiguration, 1), {}, {}).ok());
    ASSERT_EQ(usb->device().state(), DeviceState::kConfigured);
  }

  // A control transfer; IN data returned in `in` (resized to what came).
  ControlResult control(const SetupPacket& s, const Bytes& out = {}, Bytes* in = nullptr) {
    Bytes buffer(s.is_in() ? s.length : 0);
    const ControlResult r = controller.control(s, out, buffer);
    if (in != nullptr) {
      buffer.resize(r.in_bytes);
      *in = buffer;
    }
    return r;
  }

  // String descriptor `index` (LANGID 0x0409) as ASCII; "<stall>" if refused.
  std::string string_descriptor(std::uint8_t index) {
    Bytes in;
    if (!control(get_descriptor(descriptor::kString, index, 255, kLangIdEnglishUs), {}, &in).ok()) return "<stall>";
    std::string s;
    for (std::size_t i = 2; i + 1 < in.size(); i += 2) s.push_back(static_cast<char>(in[i]));
    return s;
  }

  static SetupPacket setup(std::uint8_t type, std::uint8_t request, std::uint16_t value, std::uint16_t index,
                           std::uint16_t length) {
    return SetupPacket{type, request, value, index, length};
  }
  static SetupPacket setup_out_device(std::uint8_t request, std::uint16_t value) {
    return {request_type(false, RequestKind::kStandard, Recipient::kDevice), request, value, 0, 0};
  }
  static SetupPacket get_descriptor(std::uint8_t type, std::uint8_t index, std::uint16_t length,
                                    std::uint16_t windex = 0) {
    return {request_type(true, RequestKind::kStandard, Recipient::kDevice), request::kGetDescriptor,
            static_cast<std::uint16_t>((type << 8) | index), windex, length};
  }
  static SetupPacket class_interface(bool in, std::uint8_t request, std::uint16_t value, std::uint8_t interface,
                                     std::uint16_t length) {
    return {request_type(in, RequestKind::kClass, Recipient::kInterface), request, value, interface, length};
  }

  std::vector<std::uint8_t> storage;
  flash::SimulatedNorFlash flash;
  FakeController controller;
  RecordingDetachHook hook;
  std::unique_ptr<firmware::HadynetRuntime<Q>> runtime;
  std::unique_ptr<link::DeviceLink<Q>> link;
  VerdictSelfTest self_test;
  std::unique_ptr<model_update::ModelSlots> slots;  // null: no model flash
  std::unique_ptr<Usb> usb;
};

// All IN packets currently available on `ep` (until NAK), concatenated;
// `packets` gets each packet's size.
inline Bytes drain_in(FakeController& c, EndpointAddress ep, std::vector<std::size_t>* packets = nullptr) {
  Bytes all;
  std::uint8_t packet[64];
  std::size_t n = 0;
  for (int guard = 0; guard < 10000; ++guard) {
    if (c.in_token(ep, packet, n) != Handshake::kAck) break;
    all.insert(all.end(), packet, packet + n);
    if (packets != nullptr) packets->push_back(n);
  }
  return all;
}

}  // namespace hadynet::usb::testing

#endif  // HADYNET_TEST_USB_USB_TEST_DEVICE_H_
