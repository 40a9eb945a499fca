// The host tools' serial path (tools/link/fd_stream.h, link_session.h) on a
// pseudo-terminal: a thread plays the device (firmware/link/device_link.h
// over the pty's master side, the same code the boards run), the host opens
// the slave side as a serial port at 115200 baud and talks the protocol.
// Results must equal a twin runtime bit for bit (same code, same inputs).
#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <memory>
#include <poll.h>
#include <pty.h>
#include <thread>
#include <unistd.h>

#include "firmware/app/synthetic_frames.h"
#include "firmware/link/device_link.h"
#include "hadynet_model_q15.h"
#include "tools/link/fd_stream.h"
#include "tools/link/link_session.h"

namespace hadynet {
namespace {

using Q = model_q15::Model;

// The device end on the pty master until `stop`.
void serve(int master, firmware::HadynetRuntime<Q>& runtime, std::atomic<bool>& stop) {
  auto device = std::make_unique<link::DeviceLink<Q>>(runtime);
  std::uint8_t buffer[256];
  while (!stop) {
    pollfd p{master, POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) continue;
    const ssize_t n = ::read(master, buffer, sizeof buffer);
    if (n <= 0) continue;
    for (ssize_t i = 0; i < n; ++i) {
      const auto reply = device->receive(buffer[i]);
      for (std::size_t done = 0; done < reply.size();) {
        const ssize_t w = ::write(master, reply.data() + done, reply.size() - done);
        if (w > 0) done += static_cast<std::size_t>(w);
      }
    }
  }
}

TEST(SerialLink, SessionOverAPtyMatchesTheRuntime) {
  int master = -1, slave = -1;
  char name[128] = {};
  ASSERT_EQ(::openpty(&master, &slave, name, nullptr, nullptr), 0);
  auto device_runtime = std::make_unique<firmware::HadynetRuntime<Q>>();
  std::atomic<bool> stop{false};
  std::thread device(serve, master, std::ref(*device_runtime), std::ref(stop));
  {
    tools::FdStream port = tools::FdStream::open_serial(name, 115200);
    tools::LinkSession<Q> session(port);
    session.connect();
    const link::InfoReply info = session.info();
    EXPECT_EQ(info.model_hash, Q::kModelHash);
    EXPECT_EQ(info.y, Q::kY);
    session.set_mode(firmware::Mode::kControl);
    auto twin = std::make_unique<firmware::HadynetRuntime<Q>>();
    twin->set_mode(firmware::Mode::kControl);
    app::SyntheticFrames<Q> frames(3);
    firmware::SensorFrame<Q> frame{};
    for (int t = 0; t < 10; ++t) {
      frames.next(frame);
      const auto a = session.step(frame);
      const auto b = twin->step(frame);
      EXPECT_EQ(std::memcmp(a.prediction, b.prediction, sizeof a.prediction), 0) << t;
      EXPECT_EQ(std::memcmp(a.command, b.command, sizeof a.command), 0) << t;
      EXPECT_EQ(a.contact, b.contact) << t;
    }
  }
  stop = true;
  device.join();
  ::close(slave);
  ::close(master);
}

TEST(SerialLink, NoDeviceIsAClearError) {
  EXPECT_THROW(tools::FdStream::open_serial("/nonexistent/tty", 115200), tools::LinkError);
  int master = -1, slave = -1;
  char name[128] = {};
  ASSERT_EQ(::openpty(&master, &slave, name, nullptr, nullptr), 0);
  tools::FdStream port = tools::FdStream::open_serial(name, 115200);
  tools::LinkSession<Q> session(port, 200);
  try {
    session.connect(600, 200);  // nobody answers on the master side
    ADD_FAILURE() << "connect succeeded without a device";
  } catch (const tools::LinkError& e) {
    EXPECT_NE(std::string(e.what()).find("did not acknowledge a reset within 600 ms"), std::string::npos) << e.what();
  }
  ::close(slave);
  ::close(master);
}

}  // namespace
}  // namespace hadynet
