// Test fixtures for the link: a device (runtime + DeviceLink) in zeroed
// memory, so that two devices that went through the same valid requests
// compare equal byte for byte; a host side that builds requests and decodes
// the replies; deterministic synthetic sensor frames.
#ifndef HADYNET_TEST_LINK_LINK_TEST_DEVICE_H_
#define HADYNET_TEST_LINK_LINK_TEST_DEVICE_H_

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <vector>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/link/device_link.h"
#include "firmware/link/link_client.h"
#include "firmware/link/messages.h"
#include "firmware/link/stream_decoder.h"

namespace hadynet::link::testing {

using Bytes = std::vector<std::uint8_t>;

template <firmware::GeneratedModel M>
struct Device {
  firmware::HadynetRuntime<M> runtime;
  DeviceLink<M> link{runtime};
};

// A Device placed in zero-filled memory: padding bytes start equal, so the
// runtime objects of twins can be compared with memcmp.
template <firmware::GeneratedModel M>
class ZeroedDevice {
 public:
  ZeroedDevice() {
    void* p = std::calloc(1, sizeof(Device<M>));
    if (p == nullptr) std::abort();
    device_ = new (p) Device<M>();
  }
  ~ZeroedDevice() {
    device_->~Device<M>();
    std::free(device_);
  }
  ZeroedDevice(const ZeroedDevice&) = delete;
  ZeroedDevice& operator=(const ZeroedDevice&) = delete;

  Device<M>* operator->() const { return device_; }
  Device<M>& operator*() const { return *device_; }

  // Feeds wire bytes; returns the replies, each decoded (COBS removed).
  std::vector<Bytes> send(const Bytes& wire) {
    std::vector<Bytes> replies;
    for (std::uint8_t b : wire) {
      const std::span<const std::uint8_t> out = device_->link.receive(b);
      if (out.empty()) continue;
      EXPECT_EQ(out.back(), 0) << "a reply ends with its delimiter";
      for (std::size_t i = 0; i + 1 < out.size(); ++i) EXPECT_NE(out[i], 0) << "a zero inside an encoded reply";
      Bytes decoded(kMaxEncodedFrame);
      const CobsDecodeResult r = cobs_decode(out.first(out.size() - 1), decoded);
      EXPECT_EQ(r.status, CobsStatus::kOk);
      decoded.resize(r.size);
      replies.push_back(decoded);
    }
    return replies;
  }

  // Sends wire bytes that must produce exactly one reply.
  Bytes send_one(const Bytes& wire) {
    const std::vector<Bytes> replies = send(wire);
    EXPECT_EQ(replies.size(), 1u);
    return replies.empty() ? Bytes{} : replies.front();
  }

 private:
  Device<M>* device_;
};

// The runtime's whole state, byte for byte, plus the link's.
template <firmware::GeneratedModel M>
void expect_same_state(const ZeroedDevice<M>& a, const ZeroedDevice<M>& b) {
  EXPECT_EQ(std::memcmp(&a->runtime, &b->runtime, sizeof(a->runtime)), 0) << "runtime bytes differ";
  EXPECT_EQ(a->runtime.mode(), b->runtime.mode());
  EXPECT_EQ(std::memcmp(a->runtime.pb(), b->runtime.pb(), sizeof(a->runtime.pb())), 0);
  EXPECT_EQ(a->link.dispatcher().synchronised(), b->link.dispatcher().synchronised());
  EXPECT_EQ(a->link.dispatcher().expected_sequence(), b->link.dispatcher().expected_sequence());
  EXPECT_EQ(a->link.decoder().pending(), b->link.decoder().pending());
}

// Request wire bytes from a LinkClient call, e.g. wire_of([&](auto w) { return c.reset(w); }).
template <class F>
Bytes wire_of(F&& build) {
  Bytes wire(kMaxWireFrame);
  const std::size_t n = build(std::span<std::uint8_t>(wire));
  EXPECT_GT(n, 0u);
  wire.resize(n);
  return wire;
}

// A decoded frame (header, payload, CRC) COBS-encoded with its delimiter.
inline Bytes encode_wire(const Bytes& decoded) {
  Bytes wire(cobs_max_encoded_size(decoded.size()) + 1);
  wire.resize(encode_for_wire(decoded, wire));
  return wire;
}

// A decoded frame with arbitrary header fields, any payload size and a
// correct CRC, assembled here byte by byte (not with the code under test).
inline Bytes make_frame(std::uint8_t version, std::uint8_t type, std::uint16_t seq, const Bytes& payload) {
  Bytes f = {version,
             type,
             static_cast<std::uint8_t>(seq),
             static_cast<std::uint8_t>(seq >> 8),
             static_cast<std::uint8_t>(payload.size()),
             static_cast<std::uint8_t>(payload.size() >> 8)};
  // Room for all of it first (also keeps GCC 12's -Warray-bounds from a
  // false positive on the insert into a 6-byte vector).
  f.reserve(f.size() + payload.size() + kCrcSize);
  f.insert(f.end(), payload.begin(), payload.end());
  const std::uint32_t crc = crc32(f);
  for (int k = 0; k < 4; ++k) f.push_back(static_cast<std::uint8_t>(crc >> (8 * k)));
  return f;
}

inline Bytes operator+(Bytes a, const Bytes& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// Deterministic sensor frame t: every channel at its mean plus a slow
// sinusoid of one standard deviation (physical units), phase-shifted per
// channel, so the network sees varied but plausible input.
template <firmware::GeneratedModel M>
firmware::SensorFrame<M> synthetic_frame(int t) {
  firmware::SensorFrame<M> f;
  for (int i = 0; i < M::kY; ++i) {
    f.y[i] = M::kYMean[i] + M::kYStd[i] * static_cast<float>(std::sin(0.37 * t + 0.5 * i));
  }
  for (int i = 0; i < M::kU; ++i) {
    f.u_prev[i] = M::kUMean[i] + M::kUStd[i] * static_cast<float>(std::cos(0.23 * t + 0.9 * i));
  }
  return f;
}

// Field-by-field bit equality of two step results.
template <firmware::GeneratedModel M>
void expect_bit_identical(const firmware::StepResult<M>& a, const firmware::StepResult<M>& b, int t) {
  EXPECT_EQ(a.prediction_valid, b.prediction_valid) << "frame " << t;
  EXPECT_EQ(a.distance_valid, b.distance_valid) << "frame " << t;
  EXPECT_EQ(a.contact, b.contact) << "frame " << t;
  EXPECT_EQ(a.command_valid, b.command_valid) << "frame " << t;
  EXPECT_EQ(std::memcmp(a.prediction, b.prediction, sizeof a.prediction), 0) << "frame " << t;
  EXPECT_EQ(std::memcmp(&a.d, &b.d, sizeof a.d), 0) << "frame " << t;
  EXPECT_EQ(std::memcmp(a.command, b.command, sizeof a.command), 0) << "frame " << t;
}

}  // namespace hadynet::link::testing

#endif  // HADYNET_TEST_LINK_LINK_TEST_DEVICE_H_
