#include "test/dfuse_sim/stm32_rom_bootloader.h"

#include <array>

#include "firmware/usb/dfu_spec.h"

namespace hadynet::usb::host_testing {

namespace {

constexpr std::uint8_t lo(std::uint16_t v) { return static_cast<std::uint8_t>(v & 0xFF); }
constexpr std::uint8_t hi(std::uint16_t v) { return static_cast<std::uint8_t>(v >> 8); }

// String indices: 1..3 identity, 4.. the alternates' memory descriptors.
constexpr std::uint8_t kStringManufacturer = 1;
constexpr std::uint8_t kStringProduct = 2;
constexpr std::uint8_t kStringSerial = 3;
constexpr std::uint8_t kStringFirstAlternate = 4;

constexpr const char* kStrings[] = {
    nullptr,  // 0: LANGID, answered by UsbDevice
    "STMicroelectronics",
    "STM32  BOOTLOADER",
    "336A35653133",  // a serial in the ROM's style (12 hex digits)
    "@Internal Flash  /0x08000000/04*016Kg,01*064Kg,07*128Kg",
    "@Option Bytes  /0x1FFFC000/01*016 e",
    "@OTP Memory /0x1FFF7800/01*512 e,01*016 e",
    "@Device Feature/0xFFFF0000/01*004 e",
};
static_assert(sizeof kStrings / sizeof kStrings[0] == kStringFirstAlternate + kDfuseAlternates);

constexpr std::uint16_t kBcdUsb = 0x0200;
constexpr std::uint16_t kBcdDevice = 0x2200;
constexpr std::uint16_t kDetachTimeoutMs = 255;
constexpr std::uint16_t kBcdDfuSe = 0x011A;  // DfuSe's DFU version
constexpr std::uint8_t kMaxPower2mA = 50;    // bMaxPower: 100 mA

constexpr std::array<std::uint8_t, 18> kDeviceDescriptor = {
    18, descriptor::kDevice, lo(kBcdUsb), hi(kBcdUsb), 0, 0, 0, static_cast<std::uint8_t>(kEp0MaxPacket),
    lo(kRomVendorId), hi(kRomVendorId), lo(kRomProductId), hi(kRomProductId), lo(kBcdDevice), hi(kBcdDevice),
    kStringManufacturer, kStringProduct, kStringSerial, 1,
};

constexpr std::size_t kConfigurationSize = 9 + 9 * kDfuseAlternates + 9;

constexpr std::array<std::uint8_t, kConfigurationSize> make_configuration() {
  std::array<std::uint8_t, kConfigurationSize> c{};
  std::size_t at = 0;
  const auto put = [&](std::initializer_list<std::uint8_t> bytes) {
    for (std::uint8_t b : bytes) c[at++] = b;
  };
  put({9, descriptor::kConfiguration, lo(kConfigurationSize), hi(kConfigurationSize), 1, 1, 0, 0xC0, kMaxPower2mA});
  for (std::uint8_t alt = 0; alt < kDfuseAlternates; ++alt) {
    put({9, descriptor::kInterface, kRomDfuInterface, alt, 0, dfu::kClassApplicationSpecific, dfu::kSubclassDfu,
         dfu::kProtocolDfuMode, static_cast<std::uint8_t>(kStringFirstAlternate + alt)});
  }
  const std::uint8_t attributes = dfu::kCanDownload | dfu::kCanUpload | dfu::kWillDetach;  // 0x0B
  put({9, descriptor::kDfuFunctional, attributes, lo(kDetachTimeoutMs), hi(kDetachTimeoutMs),
       lo(kDfuseTransferSize), hi(kDfuseTransferSize), lo(kBcdDfuSe), hi(kBcdDfuSe)});
  return c;
}

constexpr std::array<std::uint8_t, kConfigurationSize> kConfiguration = make_configuration();

const DescriptorSet kDescriptors{kDeviceDescriptor, kConfiguration, kStrings};

}  // namespace

Stm32RomBootloader::Stm32RomBootloader(const DfuseFaults& faults)
    : faults_(faults),
      dfu_(flash_, faults_, kRomDfuInterface),
      bridge_(controller_, dfu_, kRomDfuInterface),
      functions_{&dfu_},
      device_(bridge_, kDescriptors, functions_, /*self_powered=*/true) {
  set_faults(faults);
  bridge_.attach(device_);
  device_.start();
}

void Stm32RomBootloader::set_faults(const DfuseFaults& faults) noexcept {
  faults_ = faults;
  flash_.set_leaky_cell(faults.leaky_cell_address, faults.leaky_cell_mask);
}

}  // namespace hadynet::usb::host_testing
