// The firmware's USB device through the real libusb (1.0.26) and the Linux
// usbfs backend, served by the umockdev testbed (usb_testbed.h) with the hand (hand_device.h). Run
// under umockdev-wrapper (CTest does). Expected values are written from
// docs/usb.md and the specs, not taken from the firmware's tables; all are
// exact (descriptors, bytes, records bit for bit). Every libusb call that
// waits has a timeout (kTimeoutMs), so a broken device fails, never hangs.
#include <gtest/gtest.h>
#include <hidapi.h>
#include <libusb.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "firmware/app/period_record.h"
#include "firmware/link/frame.h"
#include "firmware/link/link_client.h"
#include "firmware/link/messages.h"
#include "firmware/link/stream_decoder.h"
#include "firmware/usb/telemetry_decoder.h"
#include "test/usb/test_bytes.h"
#include "test/usb_host/hand_device.h"
#include "test/usb_host/model_image_files.h"
#include "test/usb_host/test_records.h"
#include "test/usb_host/usb_testbed.h"

namespace hadynet::usb::host_testing {
namespace {

constexpr unsigned kTimeoutMs = 1000;

class UsbHost : public ::testing::Test {
 protected:
  void SetUp() override {
    bus_ = std::make_unique<UsbTestbed>();
    ASSERT_TRUE(bus_->ok()) << bus_->error();
    hand_ = std::make_shared<HandDevice>();
    ASSERT_TRUE(bus_->plug(kHandDevnum, hand_)) << bus_->error();
    ASSERT_EQ(libusb_init(&ctx_), 0);
  }
  void TearDown() override {
    if (handle_ != nullptr) libusb_close(handle_);
    if (ctx_ != nullptr) libusb_exit(ctx_);
    if (bus_ != nullptr) {
      const UsbNodeStats st = bus_->stats(kHandDevnum);
      RecordProperty("usbfs_ioctls", std::to_string(st.ioctls));
      RecordProperty("urbs", std::to_string(st.urbs_submitted) + " submitted, " + std::to_string(st.urbs_reaped) +
                                 " reaped, " + std::to_string(st.urbs_discarded) + " discarded, " +
                                 std::to_string(st.naks) + " NAKs");
      EXPECT_EQ(st.unknown_ioctls, 0u) << "last: 0x" << std::hex << st.last_unknown_ioctl;
    }
    bus_.reset();
  }

  // Opens 1209:0001 into handle_ (fails the test if it cannot).
  void open() {
    handle_ = libusb_open_device_with_vid_pid(ctx_, kVid, kPid);
    ASSERT_NE(handle_, nullptr);
  }

  std::string string_descriptor(std::uint8_t index) {
    unsigned char text[256] = {};
    const int n = libusb_get_string_descriptor_ascii(handle_, index, text, sizeof text);
    if (n < 0) return std::string("<error ") + libusb_error_name(n) + ">";
    return std::string(reinterpret_cast<const char*>(text), static_cast<std::size_t>(n));
  }

  void publish(const app::PeriodRecord<Q>& r) {
    bus_->locked([&] { hand_->publish(r); });
  }

  std::unique_ptr<UsbTestbed> bus_;
  std::shared_ptr<HandDevice> hand_;
  libusb_context* ctx_ = nullptr;
  libusb_device_handle* handle_ = nullptr;
};

// ---- (a) enumeration and descriptors ----

TEST_F(UsbHost, DeviceListHasExactlyTheHand) {
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(ctx_, &list);
  ASSERT_GE(n, 0) << libusb_error_name(static_cast<int>(n));
  int hands = 0;
  for (ssize_t i = 0; i < n; ++i) {
    libusb_device_descriptor d{};
    ASSERT_EQ(libusb_get_device_descriptor(list[i], &d), 0);
    if (d.idVendor != kVid || d.idProduct != kPid) continue;
    ++hands;
    EXPECT_EQ(libusb_get_bus_number(list[i]), UsbTestbed::kBusnum);
    EXPECT_EQ(libusb_get_device_address(list[i]), kHandDevnum);
    EXPECT_EQ(libusb_get_device_speed(list[i]), LIBUSB_SPEED_FULL);
  }
  EXPECT_EQ(n, 1);
  EXPECT_EQ(hands, 1);
  libusb_free_device_list(list, 1);
}

TEST_F(UsbHost, DeviceDescriptorParses) {
  libusb_device** list = nullptr;
  ASSERT_EQ(libusb_get_device_list(ctx_, &list), 1);
  libusb_device_descriptor d{};
  ASSERT_EQ(libusb_get_device_descriptor(list[0], &d), 0);
  libusb_free_device_list(list, 1);
  EXPECT_EQ(d.bLength, 18);
  EXPECT_EQ(d.bDescriptorType, LIBUSB_DT_DEVICE);
  EXPECT_EQ(d.bcdUSB, 0x0200);
  EXPECT_EQ(d.bDeviceClass, 0xEF);  // miscellaneous, IAD composite
  EXPECT_EQ(d.bDeviceSubClass, 0x02);
  EXPECT_EQ(d.bDeviceProtocol, 0x01);
  EXPECT_EQ(d.bMaxPacketSize0, 64);
  EXPECT_EQ(d.idVendor, kVid);
  EXPECT_EQ(d.idProduct, kPid);
  EXPECT_EQ(d.bcdDevice, 0x0100);
  EXPECT_EQ(d.iManufacturer, 1);
  EXPECT_EQ(d.iProduct, 2);
  EXPECT_EQ(d.iSerialNumber, 3);
  EXPECT_EQ(d.bNumConfigurations, 1);
}

struct ExpectedEndpoint {
  std::uint8_t address;
  std::uint8_t type;  // LIBUSB_TRANSFER_TYPE_*
  std::uint16_t max_packet;
  std::uint8_t interval;
};

void expect_interface(const libusb_interface& i, int alternates, std::uint8_t number, std::uint8_t cls,
                      std::uint8_t sub, std::uint8_t proto, std::vector<ExpectedEndpoint> endpoints) {
  ASSERT_EQ(i.num_altsetting, alternates) << "interface " << int(number);
  for (int a = 0; a < alternates; ++a) {
    const libusb_interface_descriptor& d = i.altsetting[a];
    EXPECT_EQ(d.bInterfaceNumber, number);
    EXPECT_EQ(d.bAlternateSetting, a);
    EXPECT_EQ(d.bInterfaceClass, cls) << "interface " << int(number);
    EXPECT_EQ(d.bInterfaceSubClass, sub) << "interface " << int(number);
    EXPECT_EQ(d.bInterfaceProtocol, proto) << "interface " << int(number);
    ASSERT_EQ(d.bNumEndpoints, endpoints.size()) << "interface " << int(number);
    for (std::size_t e = 0; e < endpoints.size(); ++e) {
      EXPECT_EQ(d.endpoint[e].bEndpointAddress, endpoints[e].address);
      EXPECT_EQ(d.endpoint[e].bmAttributes & 3, endpoints[e].type) << int(endpoints[e].address);
      EXPECT_EQ(d.endpoint[e].wMaxPacketSize, endpoints[e].max_packet) << int(endpoints[e].address);
      EXPECT_EQ(d.endpoint[e].bInterval, endpoints[e].interval) << int(endpoints[e].address);
    }
  }
}

TEST_F(UsbHost, ConfigurationDescriptorParsesIntoFourFunctions) {
  libusb_device** list = nullptr;
  ASSERT_EQ(libusb_get_device_list(ctx_, &list), 1);
  libusb_config_descriptor* c = nullptr;
  ASSERT_EQ(libusb_get_config_descriptor(list[0], 0, &c), 0);
  libusb_config_descriptor* active = nullptr;
  ASSERT_EQ(libusb_get_active_config_descriptor(list[0], &active), 0);  // from sysfs bConfigurationValue
  EXPECT_EQ(active->bConfigurationValue, 1);
  libusb_free_config_descriptor(active);
  libusb_free_device_list(list, 1);

  EXPECT_EQ(c->bConfigurationValue, 1);
  EXPECT_EQ(c->bNumInterfaces, 5);
  EXPECT_EQ(c->iConfiguration, 10);
  EXPECT_EQ(c->bmAttributes, 0xC0);  // self-powered
  EXPECT_EQ(c->MaxPower, 50);        // 100 mA in 2 mA units
  // The CDC function's IAD precedes interface 0: libusb 1.0.26 leaves it in
  // the configuration's extra bytes.
  ASSERT_GE(c->extra_length, 8);
  const std::uint8_t iad[] = {8, 0x0B, 0, 2, 0x02, 0x02, 0x00};  // first 0, count 2, CDC ACM
  EXPECT_EQ(std::memcmp(c->extra, iad, sizeof iad), 0);

  const auto in = LIBUSB_ENDPOINT_IN;
  expect_interface(c->interface[0], 1, 0, 0x02, 0x02, 0x00, {{0x81, LIBUSB_TRANSFER_TYPE_INTERRUPT, 16, 16}});
  expect_interface(c->interface[1], 1, 1, 0x0A, 0x00, 0x00,
                   {{0x02, LIBUSB_TRANSFER_TYPE_BULK, 64, 0}, {in | 2, LIBUSB_TRANSFER_TYPE_BULK, 64, 0}});
  expect_interface(c->interface[2], 1, 2, 0x03, 0x00, 0x00, {{0x83, LIBUSB_TRANSFER_TYPE_INTERRUPT, 64, 10}});
  expect_interface(c->interface[3], 1, 3, 0xFE, 0x01, 0x01, {});
  expect_interface(c->interface[4], 2, 4, 0xFE, 0x01, 0x02, {});
  // DFU functional descriptors (9 bytes, type 0x21): runtime 0x0B, mode 0x07.
  ASSERT_EQ(c->interface[3].altsetting[0].extra_length, 9);
  EXPECT_EQ(c->interface[3].altsetting[0].extra[1], 0x21);
  EXPECT_EQ(c->interface[3].altsetting[0].extra[2], 0x0B);
  for (int a = 0; a < 2; ++a) {
    ASSERT_EQ(c->interface[4].altsetting[a].extra_length, 9);
    EXPECT_EQ(c->interface[4].altsetting[a].extra[2], 0x07);
  }
  libusb_free_config_descriptor(c);
}

TEST_F(UsbHost, WireDescriptorsEqualSysfsAndStringsReadBack) {
  open();
  // GET_DESCRIPTOR over EP0 (control URBs) gives what sysfs holds.
  std::vector<std::uint8_t> buffer(1024);
  int n = libusb_get_descriptor(handle_, LIBUSB_DT_DEVICE, 0, buffer.data(), 18);
  ASSERT_EQ(n, 18) << libusb_error_name(n);
  EXPECT_EQ(std::vector<std::uint8_t>(buffer.begin(), buffer.begin() + n),
            bus_->enumerated(kHandDevnum).device_descriptor);
  n = libusb_get_descriptor(handle_, LIBUSB_DT_CONFIG, 0, buffer.data(), static_cast<int>(buffer.size()));
  ASSERT_GT(n, 0) << libusb_error_name(n);
  EXPECT_EQ(std::vector<std::uint8_t>(buffer.begin(), buffer.begin() + n), bus_->enumerated(kHandDevnum).configuration);

  EXPECT_EQ(string_descriptor(1), "HADYNET project");
  EXPECT_EQ(string_descriptor(2), "HADYNET forearm");
  EXPECT_EQ(string_descriptor(3), kFixtureSerial);  // the unique ID as 24 upper-case hex digits
  EXPECT_EQ(
      string_descriptor(10), std::string("fw ") + kFixtureFirmwareVersion + " model " + [] {
        char h[17];
        std::snprintf(h, sizeof h, "%016llx", static_cast<unsigned long long>(Q::kModelHash));
        return std::string(h) + " (factory)";  // no image in the slots: the compiled-in model runs
      }());
  // Device qualifier: STALL (full speed only) → LIBUSB_ERROR_PIPE.
  EXPECT_EQ(libusb_get_descriptor(handle_, 0x06 /* device qualifier */, 0, buffer.data(), 10), LIBUSB_ERROR_PIPE);
  // The stall was protocol only: EP0 works again.
  EXPECT_EQ(string_descriptor(2), "HADYNET forearm");
  int configuration = -1;
  ASSERT_EQ(libusb_get_configuration(handle_, &configuration), 0);
  EXPECT_EQ(configuration, 1);
}

// ---- (b) the link over the CDC bulk endpoints ----

// Reads bulk IN until one reply frame decodes (or the deadline passes).
link::Reply read_reply(libusb_device_handle* h, link::LinkClient<Q>& client, link::StreamDecoder& rx,
                       std::vector<std::uint8_t>& frame) {
  for (int attempt = 0; attempt < 20; ++attempt) {
    std::uint8_t in[512];
    int got = 0;
    const int r = libusb_bulk_transfer(h, 0x82, in, sizeof in, &got, kTimeoutMs);
    if (r != 0 && r != LIBUSB_ERROR_TIMEOUT) {
      ADD_FAILURE() << "bulk IN: " << libusb_error_name(r);
      return {};
    }
    for (int i = 0; i < got; ++i) {
      if (rx.push(in[i]) != link::StreamDecoder::Event::kFrame) continue;
      frame.assign(rx.frame().begin(), rx.frame().end());
      EXPECT_EQ(i, got - 1) << "bytes after the reply frame";
      return client.accept(frame);
    }
  }
  ADD_FAILURE() << "no reply frame";
  return {};
}

void send_frame(libusb_device_handle* h, std::span<const std::uint8_t> wire) {
  int sent = 0;
  const int r = libusb_bulk_transfer(h, 0x02, const_cast<std::uint8_t*>(wire.data()), static_cast<int>(wire.size()),
                                     &sent, kTimeoutMs);
  ASSERT_EQ(r, 0) << libusb_error_name(r);
  ASSERT_EQ(sent, static_cast<int>(wire.size()));
}

TEST_F(UsbHost, LinkResetAndInfoOverCdcBulk) {
  open();
  ASSERT_EQ(libusb_claim_interface(handle_, 1), 0);
  link::LinkClient<Q> client;
  link::StreamDecoder rx;
  std::vector<std::uint8_t> frame;
  std::uint8_t wire[link::kMaxWireFrame];

  const std::uint16_t reset_sequence = client.next_sequence();
  send_frame(handle_, std::span(wire, client.reset(wire)));
  const link::Reply reset = read_reply(handle_, client, rx, frame);
  ASSERT_TRUE(reset.ok()) << reset.status.reason;
  EXPECT_EQ(reset.type, link::MessageType::kResetAck);
  EXPECT_EQ(reset.sequence, reset_sequence);

  const std::uint16_t info_sequence = client.next_sequence();
  send_frame(handle_, std::span(wire, client.info_request(wire)));
  const link::Reply info = read_reply(handle_, client, rx, frame);
  ASSERT_TRUE(info.ok()) << info.status.reason;
  EXPECT_EQ(info.type, link::MessageType::kInfo);
  EXPECT_EQ(info.sequence, info_sequence);
  link::InfoReply decoded;
  ASSERT_TRUE(link::decode_info(info.payload, decoded));
  EXPECT_EQ(decoded.model_hash, Q::kModelHash);
  EXPECT_EQ(decoded.x, Q::kX);
  EXPECT_EQ(decoded.u, Q::kU);
  EXPECT_EQ(decoded.y, Q::kY);
  EXPECT_EQ(libusb_release_interface(handle_, 1), 0);
}

// What host software does at start-up (pyserial-like tools, libusb CDC
// drivers): CLEAR_FEATURE(ENDPOINT_HALT) on endpoints that are not halted,
// SET_INTERFACE(alt 0) on single-alternate interfaces, a port reset. The
// functions must keep working after each.
TEST_F(UsbHost, ClearHaltSetInterfaceAndResetKeepTheLinkWorking) {
  open();
  ASSERT_EQ(libusb_set_configuration(handle_, 1), 0);  // the same configuration again: a light reset
  ASSERT_EQ(libusb_claim_interface(handle_, 1), 0);
  link::LinkClient<Q> client;
  link::StreamDecoder rx;
  std::vector<std::uint8_t> frame;
  std::uint8_t wire[link::kMaxWireFrame];
  const auto info_round_trip = [&](const char* after) {
    send_frame(handle_, std::span(wire, client.info_request(wire)));
    const link::Reply r = read_reply(handle_, client, rx, frame);
    EXPECT_TRUE(r.ok()) << "after " << after << ": " << r.status.reason;
    EXPECT_EQ(r.type, link::MessageType::kInfo) << "after " << after;
  };
  info_round_trip("SET_CONFIGURATION(1) and claim");
  ASSERT_EQ(libusb_clear_halt(handle_, 0x02), 0);
  ASSERT_EQ(libusb_clear_halt(handle_, 0x82), 0);
  info_round_trip("CLEAR_FEATURE(ENDPOINT_HALT) on 0x02 and 0x82");
  ASSERT_EQ(libusb_set_interface_alt_setting(handle_, 1, 0), 0);
  info_round_trip("SET_INTERFACE(1, 0)");
  ASSERT_EQ(libusb_reset_device(handle_), 0);
  ASSERT_EQ(libusb_claim_interface(handle_, 1), 0);
  client = {};
  rx = {};
  send_frame(handle_, std::span(wire, client.reset(wire)));
  EXPECT_EQ(read_reply(handle_, client, rx, frame).type, link::MessageType::kResetAck);
  info_round_trip("a port reset");
}

TEST_F(UsbHost, ClearHaltOnTheHidEndpointKeepsTelemetryFlowing) {
  open();
  ASSERT_EQ(libusb_claim_interface(handle_, 2), 0);
  ASSERT_EQ(libusb_clear_halt(handle_, 0x83), 0);
  publish(record(1));
  std::uint8_t report[64];
  int got = 0;
  TelemetryDecoder<Q> decoder;
  for (int part = 0; part < 4; ++part) {
    const int r = libusb_interrupt_transfer(handle_, 0x83, report, sizeof report, &got, kTimeoutMs);
    ASSERT_EQ(r, 0) << libusb_error_name(r) << " part " << part;
    decoder.push(std::span<const std::uint8_t>(report, static_cast<std::size_t>(got)));
  }
  EXPECT_EQ(decoder.stats().records, 1u);
}

struct AsyncDone {
  bool done = false;
  libusb_transfer_status status = LIBUSB_TRANSFER_ERROR;
  int actual = 0;
};

void LIBUSB_CALL on_async_done(libusb_transfer* t) {
  auto* d = static_cast<AsyncDone*>(t->user_data);
  d->done = true;
  d->status = t->status;
  d->actual = t->actual_length;
}

// 40 requests in one bulk OUT transfer: their replies (~2.8 kB) exceed the
// device's transmit ring (2 x 513 bytes), so it stops taking OUT packets
// (NAK) until the host reads replies. The OUT URB stays pending meanwhile
// and completes whole; every reply arrives, in order.
TEST_F(UsbHost, BackToBackRequestsAreFlowControlledNotLost) {
  open();
  ASSERT_EQ(libusb_claim_interface(handle_, 1), 0);
  constexpr int kRequests = 40;
  link::LinkClient<Q> client;
  std::vector<std::uint8_t> out;
  std::uint8_t wire[link::kMaxWireFrame];
  for (int i = 0; i < kRequests; ++i) {
    client.set_next_sequence(static_cast<std::uint16_t>(i));
    const std::size_t n = client.info_request(wire);
    out.insert(out.end(), wire, wire + n);
  }
  AsyncDone done;
  libusb_transfer* t = libusb_alloc_transfer(0);
  libusb_fill_bulk_transfer(t, handle_, 0x02, out.data(), static_cast<int>(out.size()), on_async_done, &done,
                            5 * kTimeoutMs);
  ASSERT_EQ(libusb_submit_transfer(t), 0);
  const std::uint64_t naks_before_reading = bus_->stats(kHandDevnum).naks;

  link::StreamDecoder rx;
  int replies = 0;
  for (int attempt = 0; attempt < 200 && replies < kRequests; ++attempt) {
    std::uint8_t in[512];
    int got = 0;
    const int r = libusb_bulk_transfer(handle_, 0x82, in, sizeof in, &got, kTimeoutMs);
    ASSERT_TRUE(r == 0 || r == LIBUSB_ERROR_TIMEOUT) << libusb_error_name(r);
    for (int i = 0; i < got; ++i) {
      if (rx.push(in[i]) != link::StreamDecoder::Event::kFrame) continue;
      const link::Reply reply = link::parse_reply(rx.frame());
      ASSERT_TRUE(reply.ok()) << reply.status.reason << " reply " << replies;
      EXPECT_EQ(reply.type, link::MessageType::kInfo);
      EXPECT_EQ(reply.sequence, replies);
      ++replies;
    }
  }
  EXPECT_EQ(replies, kRequests);
  for (int i = 0; i < 100 && !done.done; ++i) {
    timeval tv{0, 10000};
    libusb_handle_events_timeout_completed(ctx_, &tv, nullptr);
  }
  ASSERT_TRUE(done.done);
  EXPECT_EQ(done.status, LIBUSB_TRANSFER_COMPLETED);
  EXPECT_EQ(done.actual, static_cast<int>(out.size()));
  EXPECT_GT(naks_before_reading, 0u) << "the OUT URB should have been NAKed before the host read";
  libusb_free_transfer(t);
}

// ---- DFU over EP0 (class requests, control OUT data stages) ----

constexpr std::uint8_t kDfuOut = 0x21;  // class, interface, host to device
constexpr std::uint8_t kDfuIn = 0xA1;   // class, interface, device to host
constexpr std::uint16_t kDfuModeInterface = 4;

// DFU_GETSTATUS until bState == `state` (the fixture does the device's
// flash work on every ioctl, so no bwPollTimeout sleep is needed); false on
// dfuERROR (10) or after 100 polls.
bool poll_dfu_state(libusb_device_handle* h, std::uint8_t state) {
  for (int i = 0; i < 100; ++i) {
    std::uint8_t status[6] = {};
    if (libusb_control_transfer(h, kDfuIn, 3, 0, kDfuModeInterface, status, 6, kTimeoutMs) != 6) return false;
    if (status[4] == state) return true;
    if (status[4] == 10) return false;
  }
  return false;
}

TEST_F(UsbHost, DfuModelImageDownloadAndUploadRoundTrip) {
  // A signed model image of the build's model (hadynet model-image).
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("hadynet_usb_host_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = make_model_image(*bus_, dir, 2);
  std::vector<std::uint8_t> image = read_file(file);  // libusb takes non-const data
  std::filesystem::remove_all(dir);
  ASSERT_GT(image.size(), 256u);

  open();
  ASSERT_EQ(libusb_claim_interface(handle_, kDfuModeInterface), 0);
  EXPECT_EQ(libusb_set_interface_alt_setting(handle_, kDfuModeInterface, 2), LIBUSB_ERROR_NOT_FOUND);
  ASSERT_EQ(libusb_set_interface_alt_setting(handle_, kDfuModeInterface, 0), 0);  // model update

  constexpr std::size_t kBlock = 256;  // the DFU functional descriptor's wTransferSize
  std::uint16_t block = 0;
  for (std::size_t off = 0; off < image.size(); off += kBlock, ++block) {
    const auto n = static_cast<std::uint16_t>(std::min(kBlock, image.size() - off));
    ASSERT_EQ(libusb_control_transfer(handle_, kDfuOut, 1, block, kDfuModeInterface, image.data() + off, n, kTimeoutMs),
              n)
        << "block " << block;
    ASSERT_TRUE(poll_dfu_state(handle_, 5)) << "dfuDNLOAD-IDLE after block " << block;
  }
  ASSERT_EQ(libusb_control_transfer(handle_, kDfuOut, 1, block, kDfuModeInterface, nullptr, 0, kTimeoutMs), 0);
  ASSERT_TRUE(poll_dfu_state(handle_, 2)) << "dfuIDLE after manifestation";

  std::vector<std::uint8_t> uploaded;
  for (std::uint16_t b = 0; b < 1000; ++b) {
    std::uint8_t in[kBlock];
    const int n = libusb_control_transfer(handle_, kDfuIn, 2, b, kDfuModeInterface, in, kBlock, kTimeoutMs);
    ASSERT_GE(n, 0) << libusb_error_name(n);
    uploaded.insert(uploaded.end(), in, in + n);
    if (n < static_cast<int>(kBlock)) break;
  }
  EXPECT_EQ(uploaded, image);
  // The hand took it into slot A; it runs after a reset (hand_device.h: a new hand over the same flash).
  bus_->locked([&] { EXPECT_EQ(hand_->slot_status(model_update::SlotId::kA).state, model_update::SlotState::kValid); });
  std::vector<std::uint8_t> cells;
  bus_->locked([&] { cells = hand_->flash_cells(); });
  const HandDevice rebooted(&cells);
  EXPECT_EQ(rebooted.boot_choice().source, model_update::ModelSource::kSlotA);
  EXPECT_EQ(rebooted.boot_choice().sequence, 2u);
}

TEST_F(UsbHost, DfuDetachReachesTheBoardHook) {
  open();
  ASSERT_EQ(libusb_claim_interface(handle_, 3), 0);
  EXPECT_EQ(libusb_control_transfer(handle_, kDfuOut, 0, 1000, 3, nullptr, 0, kTimeoutMs), 0);
  int detaches = 0;
  bus_->locked([&] { detaches = hand_->detach_requests(); });
  EXPECT_EQ(detaches, 1);
}

// ---- (c) HID telemetry over the interrupt endpoint ----

TEST_F(UsbHost, HidReportsDecodeToThePublishedRecords) {
  open();
  ASSERT_EQ(libusb_claim_interface(handle_, 2), 0);
  std::uint8_t report[64];
  int got = 0;
  // Nothing published yet: the endpoint NAKs, libusb times out and discards
  // the URB.
  EXPECT_EQ(libusb_interrupt_transfer(handle_, 0x83, report, sizeof report, &got, 50), LIBUSB_ERROR_TIMEOUT);
  EXPECT_EQ(got, 0);
  EXPECT_EQ(bus_->stats(kHandDevnum).urbs_discarded, 1u);

  TelemetryDecoder<Q> decoder;
  for (std::uint32_t sequence = 1; sequence <= 3; ++sequence) {
    const app::PeriodRecord<Q> sent = record(sequence);
    publish(sent);
    bool delivered = false;
    for (int part = 0; part < 4 && !delivered; ++part) {  // the hand's model: 4 reports per record
      const int r = libusb_interrupt_transfer(handle_, 0x83, report, sizeof report, &got, kTimeoutMs);
      ASSERT_EQ(r, 0) << libusb_error_name(r) << " sequence " << sequence << " part " << part;
      ASSERT_EQ(got, 64);
      EXPECT_EQ(report[1], part);
      delivered = decoder.push(std::span<const std::uint8_t>(report, 64)) == TelemetryDecoder<Q>::Event::kRecord;
    }
    ASSERT_TRUE(delivered) << "sequence " << sequence;
    expect_same_bits(decoder.record(), sent);
  }
  EXPECT_EQ(decoder.stats().records, 3u);
  EXPECT_EQ(decoder.stats().dropped, 0u);
  EXPECT_EQ(decoder.stats().bad_reports, 0u);
}

// ---- faults ----

TEST_F(UsbHost, InjectedStallFailsOneTransferOnly) {
  open();
  ASSERT_EQ(libusb_claim_interface(handle_, 2), 0);
  bus_->fail_next_transfer(kHandDevnum, 0x83, EPIPE);
  publish(record(1));
  std::uint8_t report[64];
  int got = 0;
  EXPECT_EQ(libusb_interrupt_transfer(handle_, 0x83, report, sizeof report, &got, kTimeoutMs), LIBUSB_ERROR_PIPE);
  EXPECT_EQ(libusb_interrupt_transfer(handle_, 0x83, report, sizeof report, &got, kTimeoutMs), 0);
  EXPECT_EQ(got, 64);
  EXPECT_EQ(report[1], 0) << "the device's first report was not consumed by the failed URB";
}

TEST_F(UsbHost, UnplugCompletesPendingTransfersWithNoDevice) {
  open();
  ASSERT_EQ(libusb_claim_interface(handle_, 2), 0);
  std::uint8_t report[64];
  AsyncDone done;
  libusb_transfer* t = libusb_alloc_transfer(0);
  libusb_fill_interrupt_transfer(t, handle_, 0x83, report, sizeof report, on_async_done, &done, 5 * kTimeoutMs);
  ASSERT_EQ(libusb_submit_transfer(t), 0);  // nothing published: stays pending
  bus_->unplug(kHandDevnum);
  for (int i = 0; i < 100 && !done.done; ++i) {
    timeval tv{0, 10000};
    libusb_handle_events_timeout_completed(ctx_, &tv, nullptr);
  }
  ASSERT_TRUE(done.done);
  EXPECT_EQ(done.status, LIBUSB_TRANSFER_NO_DEVICE);
  libusb_free_transfer(t);
  int got = 0;
  EXPECT_EQ(libusb_interrupt_transfer(handle_, 0x83, report, sizeof report, &got, kTimeoutMs), LIBUSB_ERROR_NO_DEVICE);
}

// ---- hidapi's libusb backend (what `hadynet monitor` uses) ----

TEST(UsbHostHidapi, EnumeratesTheTelemetryInterfaceAndReadsRecords) {
  UsbTestbed bus;
  ASSERT_TRUE(bus.ok()) << bus.error();
  auto hand = std::make_shared<HandDevice>();
  ASSERT_TRUE(bus.plug(kHandDevnum, hand)) << bus.error();
  ASSERT_EQ(hid_init(), 0);
  hid_device_info* list = hid_enumerate(kVid, kPid);
  int found = 0;
  std::string path;
  for (hid_device_info* i = list; i != nullptr; i = i->next) {
    ++found;
    path = i->path;
    EXPECT_EQ(i->interface_number, 2);
    EXPECT_EQ(narrow(i->serial_number), kFixtureSerial);
    EXPECT_EQ(narrow(i->product_string), "HADYNET forearm");
    EXPECT_EQ(narrow(i->manufacturer_string), "HADYNET project");
  }
  hid_free_enumeration(list);
  ASSERT_EQ(found, 1) << "exactly one HID interface";
  hid_device* h = hid_open_path(path.c_str());
  ASSERT_NE(h, nullptr);

  TelemetryDecoder<Q> decoder;
  for (std::uint32_t sequence = 1; sequence <= 3; ++sequence) {
    const app::PeriodRecord<Q> sent = record(sequence);
    bus.locked([&] { hand->publish(sent); });
    bool delivered = false;
    for (int part = 0; part < 4 && !delivered; ++part) {
      std::uint8_t report[64];
      const int n = hid_read_timeout(h, report, sizeof report, static_cast<int>(kTimeoutMs));
      ASSERT_EQ(n, 64) << "sequence " << sequence << " part " << part;
      delivered = decoder.push(std::span<const std::uint8_t>(report, 64)) == TelemetryDecoder<Q>::Event::kRecord;
    }
    ASSERT_TRUE(delivered) << "sequence " << sequence;
    expect_same_bits(decoder.record(), sent);
  }
  EXPECT_EQ(decoder.stats().dropped, 0u);
  hid_close(h);
  hid_exit();  // its libusb context exits before the device goes
  EXPECT_EQ(bus.stats(kHandDevnum).unknown_ioctls, 0u) << "last: 0x" << std::hex
                                                       << bus.stats(kHandDevnum).last_unknown_ioctl;
}

}  // namespace
}  // namespace hadynet::usb::host_testing
