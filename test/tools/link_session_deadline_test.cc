// Issue 19, finding 8: a host exchange with a noisy or stale device ends in
// bounded time. Before, the time-outs applied per read, so a device sending a
// byte every 50 ms, or answering with a wrong sequence number forever, kept
// `hadynet link info` and `replay --target tcp` waiting past 60 s.
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <string>
#include <thread>

#include "firmware/link/frame.h"
#include "hadynet_model_q15.h"
#include "tools/link/link_session.h"

namespace hadynet {
namespace {

using Q = model_q15::Model;
using Clock = std::chrono::steady_clock;

// A device that never answers properly: every `period_ms` it offers the
// next bytes of `pattern`, forever. Writes are swallowed.
class EndlessDevice : public tools::ByteStream {
 public:
  EndlessDevice(std::basic_string<std::uint8_t> pattern, int period_ms)
      : pattern_(std::move(pattern)), period_ms_(period_ms) {}
  void write(std::span<const std::uint8_t>) override {}
  std::size_t read(std::span<std::uint8_t> buffer, int timeout_ms) override {
    if (timeout_ms < period_ms_) {
      std::this_thread::sleep_for(std::chrono::milliseconds(timeout_ms));
      return 0;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(period_ms_));
    const std::size_t n = std::min(buffer.size(), pattern_.size());
    for (std::size_t i = 0; i < n; ++i) buffer[i] = pattern_[(next_ + i) % pattern_.size()];
    next_ = (next_ + n) % pattern_.size();
    return n;
  }
  const std::string& name() const override { return name_; }

 private:
  std::basic_string<std::uint8_t> pattern_;
  int period_ms_;
  std::size_t next_ = 0;
  std::string name_ = "endless-device";
};

// A well-formed reply frame on the wire, for a request the host never sent.
std::basic_string<std::uint8_t> stale_reply() {
  std::uint8_t frame[link::kMaxFrame];
  link::FrameBuilder builder(frame);
  const std::size_t size = builder.finish(link::MessageType::kResetAck, 0xBEEF, 0);
  std::uint8_t wire[link::kMaxWireFrame];
  const std::size_t n = link::encode_for_wire(std::span<const std::uint8_t>(frame, size), wire);
  return {wire, wire + n};
}

// The exchange must end within its time-out plus scheduling slack: 300 ms
// time-out, 1.5 s bound (5x), far below the 60 s it ran before.
constexpr int kTimeoutMs = 300;
constexpr double kBoundS = 1.5;

std::string exchange_error(tools::ByteStream& device, double& seconds) {
  tools::LinkSession<Q> session(device, kTimeoutMs);
  const auto start = Clock::now();
  std::string error;
  try {
    session.info();
  } catch (const tools::LinkError& e) {
    error = e.what();
  }
  seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return error;
}

TEST(LinkSessionDeadline, NoiseEveryFiftyMillisecondsEndsTheExchange) {
  EndlessDevice noise({0x55}, 50);  // never a delimiter: never a frame
  double seconds = 0;
  const std::string error = exchange_error(noise, seconds);
  EXPECT_LT(seconds, kBoundS);
  EXPECT_NE(error.find("endless-device: no reply to request"), std::string::npos) << error;
  EXPECT_NE(error.find("within 300 ms (it sent"), std::string::npos) << error;
  EXPECT_NE(error.find("0 complete frames"), std::string::npos) << error;
}

TEST(LinkSessionDeadline, RepliesWithAWrongSequenceForeverEndTheExchange) {
  EndlessDevice stale(stale_reply(), 20);
  double seconds = 0;
  const std::string error = exchange_error(stale, seconds);
  EXPECT_LT(seconds, kBoundS);
  EXPECT_NE(error.find("replies to other requests"), std::string::npos) << error;
  EXPECT_EQ(error.find(" 0 of them replies"), std::string::npos) << "the stale replies were not counted: " << error;
}

TEST(LinkSessionDeadline, ConnectToANoisyDeviceEnds) {
  EndlessDevice noise({0x55}, 50);
  tools::LinkSession<Q> session(noise, kTimeoutMs);
  const auto start = Clock::now();
  try {
    session.connect(kTimeoutMs, 100);
    ADD_FAILURE() << "connected to a device that never acknowledged";
  } catch (const tools::LinkError& e) {
    EXPECT_NE(std::string(e.what()).find("did not acknowledge a reset within 300 ms"), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - start).count(), kBoundS);
}

}  // namespace
}  // namespace hadynet
