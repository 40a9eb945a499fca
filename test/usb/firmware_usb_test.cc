// The firmware's USB side (firmware/app/usb_link.cc, as linked into the
// stm32f405 image) on a host board port: this file implements
// boards/board_usb.h over the host backend (FakeController, a simulated NOR
// flash laid out like the F405's, a recording detach hook). What it checks:
// the composite device comes up on the board's port with the serial number
// from the unique ID and the firmware version; the UART and the USB CDC-ACM
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

#include "boards/board_usb.h"
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
  std::array<usb::DfuTarget, usb::composite::kDfuAlternates> slots{usb::DfuTarget{t::kSlotB, true, true},
                                                                   usb::DfuTarget{t::kSlotA, false, true}};
  UsbPort port{controller, flash, slots, detach, t::kTestUid};
  int polls = 0;
};

HostPort& host_port() {
  static HostPort* port = new HostPort;  // lives as long as the firmware's statics
  return *port;
}

}  // namespace

const UsbPort* usb_port() noexcept { return &host_port().port; }
void usb_poll() noexcept { ++host_port().polls; }

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

TEST(FirmwareUsb, TheUartAndUsbServeOneDeviceStateAndThePeriodReachesHid) {
  auto runtime = std::make_unique<firmware::HadynetRuntime<Q>>();
  auto uart = std::make_unique<app::UartEndpoint<Q>>(*runtime);
  app::usb_start(uart->dispatcher());
  app::usb_start(uart->dispatcher());  // a second start changes nothing
  FakeController& c = board::host_port().controller;

  // Enumeration on the board's port; the serial number is the unique ID.
  c.bus_reset();
  ASSERT_TRUE(c.control(UsbTestDevice::setup_out_device(request::kSetAddress, 7), {}, {}).ok());
  ASSERT_TRUE(c.control(UsbTestDevice::setup_out_device(request::kSetConfiguration, 1), {}, {}).ok());
  EXPECT_EQ(string_descriptor(c, composite::string_index::kSerial), kTestUidHex);
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(Q::kModelHash));
  EXPECT_EQ(string_descriptor(c, composite::string_index::kVersion),
            std::string("fw ") + HADYNET_FIRMWARE_VERSION + " model " + hash);

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

}  // namespace
}  // namespace hadynet::usb::testing
