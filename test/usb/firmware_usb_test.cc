// The firmware's USB side (firmware/app/usb_link.cc, as linked into the
// stm32f405 image) on a host board port: this file implements
// boards/board_usb.h and board::model_flash() over the host backend
// (FakeController, a simulated NOR flash laid out like the F405's with its
// two model slots, a recording detach hook), and boots a signed image in
// slot A with the app's own boot rule and self-test (model_store.h) before
// usb_start(), as firmware_main.cc does. What it checks: the composite
// device comes up on the board's port with the serial number from the
// unique ID, the firmware version and the model the boot rule chose; the
// DFU model interface reads that image back and takes a newer one into the
// other slot through the firmware's own usb_service(); the UART and the USB CDC-ACM
// port serve ONE device state (one dispatcher: runtime, autonomous loop,
// sequence numbers), with each port's frames kept apart even when their
// bytes interleave; and a period published by the main loop reaches the host
// as HID telemetry with the same bits the link's period result carries.
// All comparisons are exact (the link and the reports carry bits).
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "boards/board.h"
#include "boards/board_usb.h"
#include "firmware/app/model_store.h"
#include "firmware/app/runtime_checksum.h"
#include "firmware/app/uart_endpoint.h"
#include "firmware/app/usb_link.h"
#include "firmware/link/link_client.h"
#include "firmware/link/messages.h"
#include "firmware/link/stream_decoder.h"
#include "firmware/usb/telemetry_decoder.h"
#include "period_record_bits.h"
#include "usb_test_device.h"

// ---- the host board port (boards/board_usb.h)
namespace hadynet::board {
namespace {

namespace t = usb::testing;

struct HostPort {
  std::vector<std::uint8_t> storage = std::vector<std::uint8_t>(flash::stm32f405::kFlashSize, 0xFF);
  flash::SimulatedNorFlash flash{flash::stm32f405::kSectors, storage};
  usb::host::FakeController controller;
  t::RecordingDetachHook detach;
  UsbPort port{controller, detach, t::kTestUid};
  ModelFlash model{flash, t::kSlotA, t::kSlotB, flash.contents()};
  int polls = 0;
};

HostPort& host_port() {
  static HostPort* port = new HostPort;  // lives as long as the firmware's statics
  return *port;
}

}  // namespace

const UsbPort* usb_port() noexcept { return &host_port().port; }
void usb_poll() noexcept { ++host_port().polls; }
const ModelFlash* model_flash() noexcept { return &host_port().model; }

}  // namespace hadynet::board

namespace hadynet::usb::testing {
namespace {

using Client = link::LinkClient<Q>;

// Feeds `wire` to the UART endpoint byte by byte; the reply bytes.
Bytes uart_exchange(app::UartEndpoint<Q>& uart, std::span<const std::uint8_t> wire) {
  Bytes out;
  for (const std::uint8_t b : wire) {
    const auto reply = uart.receive(b);
    out.insert(out.end(), reply.begin(), reply.end());
  }
  return out;
}

// Sends `wire` over CDC bulk OUT (64-byte packets), runs the main loop's
// USB service and returns what bulk IN carried.
Bytes cdc_exchange(FakeController& c, std::span<const std::uint8_t> wire) {
  Bytes in;
  std::size_t sent = 0;
  for (int guard = 0; guard < 1000 && sent < wire.size(); ++guard) {
    const std::size_t n = std::min<std::size_t>(64, wire.size() - sent);
    const Handshake h = c.out_token(composite::kCdcDataOut, wire.subspan(sent, n));
    EXPECT_NE(h, Handshake::kStall);
    if (h == Handshake::kAck) sent += n;
    app::usb_service();
    const Bytes chunk = drain_in(c, composite::kCdcDataIn);
    in.insert(in.end(), chunk.begin(), chunk.end());
  }
  for (int i = 0; i < 4; ++i) {
    app::usb_service();
    const Bytes chunk = drain_in(c, composite::kCdcDataIn);
    in.insert(in.end(), chunk.begin(), chunk.end());
  }
  return in;
}

// The replies in `bytes`, passed through `client` (which checks sequence
// numbers); their types.
std::vector<link::MessageType> replies(Client& client, const Bytes& bytes, std::vector<Bytes>* payloads = nullptr) {
  link::StreamDecoder rx;
  std::vector<link::MessageType> types;
  for (const std::uint8_t b : bytes) {
    if (rx.push(b) != link::StreamDecoder::Event::kFrame) continue;
    const link::Reply r = link::parse_reply(rx.frame());
    EXPECT_TRUE(r.status.ok());
    client.accept(rx.frame());
    types.push_back(r.type);
    if (payloads != nullptr) payloads->emplace_back(r.payload.begin(), r.payload.end());
  }
  return types;
}

std::string string_descriptor(FakeController& c, std::uint8_t index) {
  Bytes buffer(255);
  const host::ControlResult r =
      c.control(UsbTestDevice::get_descriptor(descriptor::kString, index, 255, 0x0409), {}, buffer);
  EXPECT_TRUE(r.ok());
  std::string s;
  for (std::size_t i = 2; i + 1 < r.in_bytes; i += 2) s.push_back(static_cast<char>(buffer[i]));
  return s;
}

namespace mu = model_update;

constexpr std::uint64_t kSlotModelHash = 0x0123456789ABCDEFull;

// The firmware's statics (firmware_main.cc): the runtime, the UART endpoint
// and the ModelSlots over the board's model flash, booted before
// usb_start(). Made once per process, like the firmware's; never destroyed.
struct FirmwareUnderTest {
  std::unique_ptr<firmware::HadynetRuntime<Q>> runtime = std::make_unique<firmware::HadynetRuntime<Q>>();
  std::unique_ptr<app::UartEndpoint<Q>> uart = std::make_unique<app::UartEndpoint<Q>>(*runtime);
  std::unique_ptr<mu::ModelSlots> slots;
  Bytes installed;  // the image in slot A, which the boot rule chose
};

std::unique_ptr<mu::ModelSlots> slots_over_board_flash() {
  const board::ModelFlash& m = *board::model_flash();
  return std::make_unique<mu::ModelSlots>(m.device, m.slot_a, m.slot_b, app::model_identity<Q>(),
                                          device_key().public_key, m.mapped);
}

// A signed image of the compiled-in model's tensors (so the app's self-test
// passes: its checksum is the compiled-in runtime's) under its own model hash.
Bytes compiled_model_image(std::uint32_t sequence) {
  mu::ModelImageHeader h = mu::test::header_for(app::model_identity<Q>(), sequence);
  h.model_hash = kSlotModelHash;
  auto reference = std::make_unique<firmware::HadynetRuntime<Q>>();
  h.self_test_checksum = static_cast<std::uint32_t>(app::runtime_checksum(*reference));
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(&firmware::kCompiledTensors<Q>);
  return mu::test::sign_image(h, std::span(bytes, sizeof(firmware::ModelTensors<Q>)), device_key());
}

FirmwareUnderTest* start_firmware() {
  auto* f = new FirmwareUnderTest;
  f->installed = compiled_model_image(1);
  {  // an earlier power-on session wrote the image into slot A
    const auto installer = slots_over_board_flash();
    VerdictSelfTest pass(true);
    installer->boot(pass);
    EXPECT_EQ(installer->begin_update(mu::test::header_of(f->installed)), mu::UpdateError::kOk);
    EXPECT_EQ(installer->append_update(mu::test::payload_of(f->installed)), mu::UpdateError::kOk);
    EXPECT_EQ(installer->finish_update(), mu::UpdateError::kOk);
  }
  // This power-on: the boot rule (the app's self-test), then usb_start().
  f->slots = slots_over_board_flash();
  app::boot_model(*f->slots, *f->runtime);
  app::usb_start(f->uart->dispatcher(), f->slots.get());
  app::usb_start(f->uart->dispatcher(), f->slots.get());  // a second start changes nothing
  return f;
}

FirmwareUnderTest& firmware_under_test() {
  static FirmwareUnderTest* f = start_firmware();
  return *f;
}

void enumerate(FakeController& c) {
  c.bus_reset();
  ASSERT_TRUE(c.control(UsbTestDevice::setup_out_device(request::kSetAddress, 7), {}, {}).ok());
  ASSERT_TRUE(c.control(UsbTestDevice::setup_out_device(request::kSetConfiguration, 1), {}, {}).ok());
}

TEST(FirmwareUsb, TheUartAndUsbServeOneDeviceStateAndThePeriodReachesHid) {
  FirmwareUnderTest& f = firmware_under_test();
  app::UartEndpoint<Q>* uart = f.uart.get();
  FakeController& c = board::host_port().controller;

  // Enumeration on the board's port; the serial number is the unique ID;
  // the configuration names the model the boot rule chose.
  enumerate(c);
  EXPECT_EQ(string_descriptor(c, composite::string_index::kSerial), kTestUidHex);
  EXPECT_EQ(string_descriptor(c, composite::string_index::kVersion),
            std::string("fw ") + HADYNET_FIRMWARE_VERSION + " model 0123456789abcdef (slot A, sequence 1)");
  EXPECT_EQ(f.slots->choice().source, mu::ModelSource::kSlotA);
  EXPECT_EQ(&f.runtime->tensors(), reinterpret_cast<const firmware::ModelTensors<Q>*>(f.slots->choice().payload.data()))
      << "the runtime reads the slot's tensors in place";

  // One session over both ports: reset and a muscle state over USB, the
  // period result over the UART; one client numbers them all.
  Client client;
  std::uint8_t wire[link::kMaxWireFrame];
  EXPECT_EQ(replies(client, cdc_exchange(c, std::span(wire, client.reset(wire)))),
            std::vector<link::MessageType>{link::MessageType::kResetAck});
  app::MuscleState<Q> muscle;
  for (int j = 0; j < app::ChannelLayout<Q>::kMuscleY; ++j) muscle.y[j] = 0.25f * static_cast<float>(j) - 1.0f;
  for (int i = 0; i < Q::kU; ++i) muscle.u_prev[i] = 0.1f * static_cast<float>(i);
  EXPECT_EQ(replies(client, cdc_exchange(c, std::span(wire, client.muscle_state(muscle, wire)))),
            std::vector<link::MessageType>{link::MessageType::kMuscleStateAck});
  EXPECT_GT(board::host_port().polls, 0) << "usb_service() polls the board's controller";

  // The main loop's period: loadcells + that muscle state -> a step.
  app::PeriodLoop<Q>& loop = uart->loop();
  app::PeriodLoop<Q>::LoadcellReading reading;
  reading.valid = true;
  for (int k = 0; k < app::ChannelLayout<Q>::kLoadcells; ++k) reading.newtons[k] = 0.5f + static_cast<float>(k);
  loop.run_period(reading, 0);
  loop.end_period(/*work_ticks=*/10, /*ticks_per_period=*/100);
  ASSERT_NE(loop.latest().flags & app::kRecordStepped, 0) << "the muscle state sent over USB fed the loop";
  app::usb_publish(loop.latest());

  // HID: the published record, bit for bit.
  TelemetryDecoder<Q> telemetry;
  const Bytes reports = drain_in(c, composite::kHidReportIn);
  ASSERT_EQ(reports.size(), 64 * TelemetryLayout<Q>::kParts);
  TelemetryDecoder<Q>::Event event = TelemetryDecoder<Q>::Event::kNone;
  for (std::size_t p = 0; p < TelemetryLayout<Q>::kParts; ++p) {
    event = telemetry.push(std::span(reports).subspan(64 * p, 64));
  }
  ASSERT_EQ(event, TelemetryDecoder<Q>::Event::kRecord);
  expect_same_bits<Q>(telemetry.record(), loop.latest());

  // The UART's period result (0x08) carries the same record.
  std::vector<Bytes> payloads;
  ASSERT_EQ(replies(client, uart_exchange(*uart, std::span(wire, client.period_result_request(wire))), &payloads),
            std::vector<link::MessageType>{link::MessageType::kPeriodResult});
  app::PeriodRecord<Q> over_uart;
  ASSERT_TRUE(link::decode_period_result<Q>(payloads[0], over_uart));
  expect_same_bits<Q>(over_uart, telemetry.record());

  // Interleaved bytes: half a UART frame, a whole USB frame, the rest of the
  // UART frame. Each port decodes its own frame; both are answered. The USB
  // request is numbered first, so it is executed first.
  std::uint8_t uart_wire[link::kMaxWireFrame];
  std::uint8_t usb_wire[link::kMaxWireFrame];
  const std::uint16_t first = client.next_sequence();
  const std::size_t usb_n = client.info_request(usb_wire);
  client.set_next_sequence(static_cast<std::uint16_t>(first + 1));
  const std::size_t uart_n = client.period_result_request(uart_wire);
  client.set_next_sequence(first);
  const std::size_t half = uart_n / 2;
  const Bytes uart_head = uart_exchange(*uart, std::span(uart_wire, half));
  EXPECT_TRUE(uart_head.empty());
  const Bytes usb_reply = cdc_exchange(c, std::span(usb_wire, usb_n));
  const Bytes uart_tail = uart_exchange(*uart, std::span(uart_wire + half, uart_n - half));
  EXPECT_EQ(replies(client, usb_reply), std::vector<link::MessageType>{link::MessageType::kInfo});
  EXPECT_EQ(replies(client, uart_tail), std::vector<link::MessageType>{link::MessageType::kPeriodResult});
}

// DFU through the firmware's own USB side: alt 1 reads back the running
// image, alt 0 takes a newer image into the other slot (usb_service() does
// the flash work), the running slot untouched; the next power-on runs it.
TEST(FirmwareUsb, TheDfuModelInterfaceReadsTheRunningImageAndTakesANewOneIntoTheOtherSlot) {
  FirmwareUnderTest& f = firmware_under_test();
  FakeController& c = board::host_port().controller;
  enumerate(c);
  const auto dfu = [](bool in, std::uint8_t request, std::uint16_t value, std::uint16_t length) {
    return UsbTestDevice::class_interface(in, request, value, composite::kDfuModeInterface, length);
  };
  const auto set_alt = [&c](std::uint16_t alt) {
    return c.control({request_type(false, RequestKind::kStandard, Recipient::kInterface), request::kSetInterface, alt,
                      composite::kDfuModeInterface, 0},
                     {}, {})
        .ok();
  };
  const auto state = [&]() {
    Bytes status(6);
    EXPECT_TRUE(c.control(dfu(true, dfu::kGetStatus, 0, 6), {}, status).ok());
    return static_cast<dfu::State>(status[4]);
  };
  const auto upload = [&]() {
    Bytes all;
    for (std::uint16_t b = 0; b < 2000; ++b) {
      Bytes block(256);
      const host::ControlResult r = c.control(dfu(true, dfu::kUpload, b, 256), {}, block);
      EXPECT_TRUE(r.ok());
      all.insert(all.end(), block.begin(), block.begin() + static_cast<long>(r.in_bytes));
      if (r.in_bytes < 256) break;
    }
    return all;
  };
  ASSERT_TRUE(set_alt(1));
  EXPECT_EQ(upload(), f.installed);

  ASSERT_TRUE(set_alt(0));
  const auto& flash = board::host_port().flash;
  const Bytes slot_a(flash.contents().begin() + kSlotA.offset, flash.contents().begin() + kSlotA.offset + kSlotA.size);
  const Bytes next = compiled_model_image(2);
  std::uint16_t block = 0;
  for (std::size_t at = 0; at < next.size(); at += 256, ++block) {
    const std::size_t n = std::min<std::size_t>(256, next.size() - at);
    ASSERT_TRUE(c.control(dfu(false, dfu::kDnload, block, static_cast<std::uint16_t>(n)),
                          std::span(next).subspan(at, n), {})
                    .ok());
    ASSERT_EQ(state(), dfu::State::kDnBusy);
    app::usb_service();  // the main loop does the flash work
    ASSERT_EQ(state(), dfu::State::kDnloadIdle) << "block " << block;
  }
  ASSERT_TRUE(c.control(dfu(false, dfu::kDnload, block, 0), {}, {}).ok());
  ASSERT_EQ(state(), dfu::State::kManifest);
  app::usb_service();
  ASSERT_EQ(state(), dfu::State::kIdle);
  EXPECT_EQ(upload(), next);
  EXPECT_EQ(Bytes(flash.contents().begin() + kSlotA.offset, flash.contents().begin() + kSlotA.offset + kSlotA.size),
            slot_a)
      << "the running slot is untouched";
  EXPECT_EQ(f.slots->slot_status(mu::SlotId::kB).state, mu::SlotState::kValid);
  // The next power-on: the app's boot rule tries slot B (sequence 2) and runs it.
  const auto next_boot = slots_over_board_flash();
  auto runtime = std::make_unique<firmware::HadynetRuntime<Q>>();
  EXPECT_EQ(app::boot_model(*next_boot, *runtime).source, mu::ModelSource::kSlotB);
}

}  // namespace
}  // namespace hadynet::usb::testing
