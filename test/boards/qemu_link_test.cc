// The firmware image in QEMU behind its real link (UART0 -> DeviceLink):
// malformed frames on the wire each get the right error reply and change
// nothing. Proof by a twin: the host runs the same q15 runtime (reference
// kernels) on the valid frames only; after every bad frame the device's next
// step result must equal the twin's bit for bit (tolerance zero: same code,
// same inputs; q15 results are bit-identical on host and MCU).
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <vector>

#include "firmware/app/synthetic_frames.h"
#include "firmware/core/hadynet_runtime.h"
#include "firmware/link/link_client.h"
#include "firmware/link/messages.h"
#include "firmware/link/stream_decoder.h"
#include "hadynet_model_q15.h"
#include "tools/link/link_session.h"
#include "tools/link/qemu_process.h"

namespace hadynet {
namespace {

using Q = model_q15::Model;
using link::ErrorCode;

class QemuLink : public ::testing::Test {
 protected:
  void SetUp() override {
    qemu_ = std::make_unique<tools::QemuProcess>(
        tools::QemuOptions{"qemu-system-arm", "mps2-an386", HADYNET_FIRMWARE_IMAGE, false, "", {}});
    tools::LinkSession<Q> session(qemu_->link());
    session.connect();  // reset: sequence numbers restart at the session's next (1)
    client_.set_next_sequence(1);
    // connect() may have sent its reset more than once (a slow machine);
    // drop the late acknowledgements so that every exchange below reads its
    // own reply.
    std::uint8_t buffer[256];
    while (qemu_->link().read(buffer, 500) > 0) {
    }
  }

  // Sends raw wire bytes and returns the next reply frame (decoded, checked).
  link::Reply exchange(const std::vector<std::uint8_t>& wire) {
    qemu_->link().write(wire);
    std::uint8_t buffer[256];
    while (true) {
      const std::size_t n = qemu_->link().read(buffer, 10000);
      if (n == 0) throw tools::LinkError("no reply");
      for (std::size_t i = 0; i < n; ++i) {
        if (rx_.push(buffer[i]) == link::StreamDecoder::Event::kFrame) {
          reply_.assign(rx_.frame().begin(), rx_.frame().end());
          return client_.accept(reply_);
        }
      }
    }
  }
  std::vector<std::uint8_t> wire(std::size_t n) { return {wire_, wire_ + n}; }

  // A valid sensor frame on device and twin; their results must be equal.
  void step_both(const firmware::SensorFrame<Q>& frame, int t) {
    const link::Reply r = exchange(wire(client_.sensor_frame(frame, wire_)));
    ASSERT_TRUE(r.ok()) << "step " << t;
    ASSERT_EQ(r.type, link::MessageType::kStepResult);
    firmware::StepResult<Q> device;
    ASSERT_TRUE(link::decode_step_result<Q>(r.payload, device));
    const firmware::StepResult<Q> host = twin_->step(frame);
    EXPECT_EQ(device.prediction_valid, host.prediction_valid) << t;
    EXPECT_EQ(std::memcmp(device.prediction, host.prediction, sizeof host.prediction), 0) << t;
    EXPECT_EQ(std::memcmp(&device.d, &host.d, sizeof host.d), 0) << t;
    EXPECT_EQ(device.contact, host.contact) << t;
    EXPECT_EQ(device.command_valid, host.command_valid) << t;
    EXPECT_EQ(std::memcmp(device.command, host.command, sizeof host.command), 0) << t;
  }

  // Expects an error reply with `code` to the bad bytes.
  void expect_error(const std::vector<std::uint8_t>& bad, ErrorCode code, const char* what) {
    const link::Reply r = exchange(bad);
    ASSERT_EQ(r.type, link::MessageType::kError) << what;
    link::ErrorReply e;
    ASSERT_TRUE(link::decode_error(r.payload, e)) << what;
    EXPECT_EQ(e.code, code) << what << ": " << e.reason;
  }

  std::unique_ptr<tools::QemuProcess> qemu_;
  std::unique_ptr<firmware::HadynetRuntime<Q>> twin_ = std::make_unique<firmware::HadynetRuntime<Q>>();
  link::LinkClient<Q> client_;
  link::StreamDecoder rx_;
  std::vector<std::uint8_t> reply_;
  std::uint8_t wire_[link::kMaxWireFrame] = {};
};

TEST_F(QemuLink, MalformedFramesGetErrorRepliesAndChangeNothing) {
  {  // control mode on both, so the plan (warm start) is state too
    const link::Reply r = exchange(wire(client_.set_mode(firmware::Mode::kControl, wire_)));
    ASSERT_TRUE(r.ok());
    twin_->set_mode(firmware::Mode::kControl);
  }
  app::SyntheticFrames<Q> frames(7);
  firmware::SensorFrame<Q> frame{};
  for (int t = 0; t < 14; ++t) {
    frames.next(frame);
    std::vector<std::uint8_t> good = wire(client_.sensor_frame(frame, wire_));
    switch (t % 7) {
      case 1: {  // one payload byte flipped: CRC mismatch
        std::vector<std::uint8_t> bad = good;
        bad[bad.size() / 2] ^= 0x01;
        if (bad[bad.size() / 2] == 0) bad[bad.size() / 2] = 0x55;  // stay inside the frame
        expect_error(bad, ErrorCode::kBadCrc, "bad CRC");
        break;
      }
      case 2: {  // cut inside a COBS block, then the delimiter
        std::vector<std::uint8_t> bad(good.begin(), good.begin() + 20);
        bad.push_back(0);
        expect_error(bad, ErrorCode::kTruncated, "truncated");
        break;
      }
      case 3: {  // 600 bytes without a delimiter
        std::vector<std::uint8_t> bad(600, 0x42);
        bad.push_back(0);
        expect_error(bad, ErrorCode::kOversize, "oversize");
        break;
      }
      case 4:
        expect_error(wire(client_.raw_frame(1, 0x33, client_.next_sequence(), {}, wire_)), ErrorCode::kUnknownType,
                     "unknown type");
        break;
      case 5:
        expect_error(wire(client_.raw_frame(1, 0x02, static_cast<std::uint16_t>(client_.next_sequence() + 5), {}, wire_)),
                     ErrorCode::kOutOfOrder, "out of order");
        break;
      case 6:
        expect_error(wire(client_.raw_frame(2, 0x01, client_.next_sequence(), {}, wire_)), ErrorCode::kBadVersion,
                     "bad version");
        break;
      default:
        break;
    }
    step_both(frame, t);
  }
}

}  // namespace
}  // namespace hadynet
