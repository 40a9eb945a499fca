// Writes the link fuzzer's seed corpus (fuzz/corpus/link): a handful of valid
// sessions and one input per kind of malformed frame, in the fuzzer's record
// format (link_fuzz_input.h), for the build's q15 model. Regenerate after a
// protocol or model-shape change:
//   build/release/fuzz/make_link_corpus fuzz/corpus/link
// Exit codes: 0 written, 1 a file could not be written, 2 usage.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/link/frame.h"
#include "firmware/link/link_client.h"
#include "firmware/link/messages.h"
#include "fuzz/link_fuzz_input.h"
#include "hadynet_model_q15.h"

namespace {

using namespace hadynet::link;
using hadynet::link::fuzz::RecordKind;
using M = hadynet::model_q15::Model;
using Bytes = std::vector<std::uint8_t>;

Bytes operator+(Bytes a, const Bytes& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// One input being assembled.
class Input {
 public:
  Input& raw(const Bytes& b) { return add(RecordKind::kRaw, b); }
  Input& repeat(std::uint8_t extra_times, const Bytes& b) {
    return add_kind(static_cast<std::uint8_t>(static_cast<unsigned>(RecordKind::kRepeat) | (extra_times << 2u)), b);
  }
  // A frame record: header (version, type, sequence, length) and payload;
  // the harness adds the CRC. in_order: the harness fixes the sequence.
  Input& frame(std::uint8_t type, const Bytes& payload, bool in_order = true, std::uint16_t seq = 0,
               std::uint8_t version = kProtocolVersion, int length_field = -1) {
    const auto length = static_cast<std::uint16_t>(length_field < 0 ? payload.size() : length_field);
    Bytes f(6 + payload.size());
    f[0] = version;
    f[1] = type;
    f[2] = static_cast<std::uint8_t>(seq);
    f[3] = static_cast<std::uint8_t>(seq >> 8);
    f[4] = static_cast<std::uint8_t>(length);
    f[5] = static_cast<std::uint8_t>(length >> 8);
    std::copy(payload.begin(), payload.end(), f.begin() + 6);
    return add(in_order ? RecordKind::kInOrderFrame : RecordKind::kFrame, f);
  }
  const Bytes& bytes() const { return bytes_; }

 private:
  Input& add(RecordKind kind, const Bytes& b) { return add_kind(static_cast<std::uint8_t>(kind), b); }
  Input& add_kind(std::uint8_t kind, const Bytes& b) {
    bytes_.push_back(kind);
    bytes_.push_back(static_cast<std::uint8_t>(b.size()));
    bytes_.push_back(static_cast<std::uint8_t>(b.size() >> 8));
    bytes_.insert(bytes_.end(), b.begin(), b.end());
    return *this;
  }
  Bytes bytes_;
};

Bytes sensor_payload(int t) {
  hadynet::firmware::SensorFrame<M> f;
  for (int i = 0; i < M::kY; ++i) f.y[i] = M::kYMean[i] + M::kYStd[i] * static_cast<float>(std::sin(0.37 * t + i));
  for (int i = 0; i < M::kU; ++i) f.u_prev[i] = M::kUMean[i];
  Bytes p(PayloadSizes<M>::kSensorFrame);
  encode_sensor_frame<M>(f, p);
  return p;
}

Bytes pb_values_payload(float first) {
  SetPbRequest<M> q;
  q.kind = PbKind::kValues;
  for (int i = 0; i < M::kPb; ++i) q.values[i] = 0.1f * static_cast<float>(i);
  q.values[0] = first;
  Bytes p(PayloadSizes<M>::kSetPbValues);
  encode_set_pb<M>(q, p);
  return p;
}

// A complete wire frame (for raw records), built with the host client.
Bytes wire_frame(std::uint8_t type, std::uint16_t seq, const Bytes& payload) {
  LinkClient<M> client;
  Bytes wire(kMaxWireFrame);
  wire.resize(client.raw_frame(kProtocolVersion, type, seq, payload, wire));
  return wire;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT_DIR\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  std::vector<std::pair<std::string, Input>> inputs;
  const auto add = [&](const std::string& name) -> Input& { return inputs.emplace_back(name, Input{}).second; };
  constexpr std::uint8_t kInfo = 0x01, kSensor = 0x02, kSetPb = 0x03, kSetMode = 0x04, kReset = 0x05;

  // ---- valid sessions
  add("valid_info").frame(kInfo, {}, false, 7);
  {
    Input& s = add("valid_detect_session");
    s.frame(kInfo, {}, false, 100).frame(kSetPb, {0x00, 0x01, 0x00}).frame(kSetMode, {0x01});
    for (int t = 0; t < M::kDetectSteps + 3; ++t) s.frame(kSensor, sensor_payload(t));
    s.frame(kReset, {}, false, 9).frame(kSensor, sensor_payload(50));
  }
  {
    Input& s = add("valid_control_session");
    s.frame(kSetMode, {0x02}, false, 65534);
    for (int t = 0; t < 3; ++t) s.frame(kSensor, sensor_payload(t));
  }
  add("valid_set_pb_values").frame(kSetPb, pb_values_payload(-0.5f), false, 1).frame(kSetMode, {0x00});
  add("valid_raw_wire").raw(Bytes{0x00, 0x00} + wire_frame(kInfo, 3, {}) + wire_frame(kSetMode, 4, {0x01}));

  // ---- one kind of malformed input each
  {
    Bytes w = wire_frame(kSetMode, 1, {0x01});
    w[3] ^= 0x40;  // a payload or CRC byte (COBS keeps the position)
    add("bad_crc").raw(w);
  }
  {
    Bytes w = wire_frame(kSensor, 1, sensor_payload(1));
    w.erase(w.begin() + 40, w.end() - 1);  // cut, keep the delimiter
    add("truncated_cobs").raw(w);
  }
  add("truncated_length_field").frame(kSensor, {0x01, 0x02}, false, 0, kProtocolVersion, 140);
  add("oversize").repeat(9, Bytes(60, 0x5A)).raw({0x00}).frame(kInfo, {}, false, 1);
  add("unknown_type").frame(0x7F, {}, false, 1).frame(0x06, {0x01});
  add("bad_version").frame(kInfo, {}, false, 5, 2);
  add("bad_payload_length").frame(kInfo, {}, false, 1).frame(kSensor, {0x00, 0x00, 0x80, 0x3F}).frame(kSetMode, {});
  add("bad_pb_values").frame(kSetPb, pb_values_payload(std::numeric_limits<float>::quiet_NaN()), false, 1);
  add("bad_pb_state").frame(kSetPb, {0x00, 0xFF, 0xFF}, false, 1).frame(kSetPb, {0x07});
  add("bad_mode").frame(kSetMode, {0x03}, false, 1);
  add("out_of_order").frame(kInfo, {}, false, 10).frame(kInfo, {}, false, 12).frame(kReset, {}, false, 500);

  for (const auto& [name, input] : inputs) {
    const std::string path = dir + "/" + name + ".bin";
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (f == nullptr || std::fwrite(input.bytes().data(), 1, input.bytes().size(), f) != input.bytes().size()) {
      std::fprintf(stderr, "make_link_corpus: cannot write %s\n", path.c_str());
      if (f != nullptr) std::fclose(f);
      return 1;
    }
    std::fclose(f);
    std::printf("%s (%zu bytes)\n", path.c_str(), input.bytes().size());
  }
  return 0;
}
