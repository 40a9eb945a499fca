// One fuzz input through a fresh device (HadynetRuntime<q15> + DeviceLink),
// with the protocol's robustness contract as the oracle (docs/protocol.md):
//   * every reply is a well-formed frame of a reply type, and every
//     non-empty received frame (the bytes between two delimiters) gets
//     exactly one reply (a lone delimiter gets none);
//   * a byte that is not a delimiter never executes anything;
//   * an error reply, or no reply, leaves the runtime and the autonomous
//     loop (firmware/app/period_loop.h) byte for byte as they were, and the
//     sequence state too;
//   * a success reply echoes the expected number (any number before the
//     first executed request and for reset) and advances it by one.
// A violation aborts (the fuzzer reports it with the input). Shared by the
// libFuzzer target and the corpus test (test/link), which runs the seeds
// through the same oracle with the regular compiler.
//
// Cost: a control-mode period is ~10^7 multiply-accumulates, tens of ms
// under the sanitizers; the harness runs the stabiliser with one epoch.
#ifndef HADYNET_FUZZ_LINK_FUZZ_HARNESS_H_
#define HADYNET_FUZZ_LINK_FUZZ_HARNESS_H_

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <span>
#include <type_traits>
#include <utility>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/link/device_link.h"
#include "firmware/link/link_client.h"
#include "fuzz/link_fuzz_input.h"
#include "hadynet_model_q15.h"

namespace hadynet::link::fuzz {

using FuzzModel = model_q15::Model;

class LinkFuzzHarness {
 public:
  using Runtime = firmware::HadynetRuntime<FuzzModel>;

  LinkFuzzHarness() {
    // Zeroed storage: padding compares equal between snapshots.
    std::memset(static_cast<void*>(&storage_), 0, sizeof storage_);
    runtime_ = new (&storage_.runtime) Runtime();
    // One optimisation epoch instead of the model's (3): every part of the
    // stabiliser still runs (rollout, BPTT, line search) at a third of the
    // cost; the fuzzer's target is the link, the stabiliser's numerics are
    // tested in test/firmware.
    runtime_->control_settings().epochs = 1;
    link_ = new (&storage_.link) DeviceLink<FuzzModel>(*runtime_);
  }
  ~LinkFuzzHarness() {
    link_->~DeviceLink<FuzzModel>();
    runtime_->~Runtime();
  }
  LinkFuzzHarness(const LinkFuzzHarness&) = delete;
  LinkFuzzHarness& operator=(const LinkFuzzHarness&) = delete;

  // Runs one input (link_fuzz_input.h).
  void run(const std::uint8_t* data, std::size_t size) {
    frame_bytes_ = 0;
    frame_replies_ = 0;
    streamed_ = 0;
    std::size_t pos = 0;
    while (pos < size && streamed_ < kMaxStreamBytes) {
      const std::uint8_t kind = data[pos];
      std::size_t length = 0;
      if (pos + 1 < size) length = data[pos + 1];
      if (pos + 2 < size) length |= static_cast<std::size_t>(data[pos + 2]) << 8;
      pos += kRecordHeader;
      if (pos > size) break;
      if (length > size - pos) length = size - pos;
      record(kind, std::span<const std::uint8_t>(data + pos, length));
      pos += length;
    }
    // A frame the input left unfinished may have had its one reply already
    // (an oversize frame is answered when it overflows).
    check(frame_replies_ <= 1);
  }

  std::size_t replies() const { return replies_; }
  std::size_t executed() const { return executed_; }

 private:
  void record(std::uint8_t kind, std::span<const std::uint8_t> bytes) {
    switch (static_cast<RecordKind>(kind & 3u)) {
      case RecordKind::kRaw:
        for (const std::uint8_t b : bytes) send(b);
        break;
      case RecordKind::kFrame:
      case RecordKind::kInOrderFrame: {
        if (bytes.size() > kMaxFrame - kCrcSize) bytes = bytes.first(kMaxFrame - kCrcSize);
        std::uint8_t frame[kMaxFrame];
        std::memcpy(frame, bytes.data(), bytes.size());
        if ((kind & 3u) == static_cast<std::uint8_t>(RecordKind::kInOrderFrame) && bytes.size() >= 4 &&
            link_->dispatcher().synchronised()) {
          const std::uint16_t seq = link_->dispatcher().expected_sequence();
          frame[2] = static_cast<std::uint8_t>(seq);
          frame[3] = static_cast<std::uint8_t>(seq >> 8);
        }
        ByteWriter crc_field(std::span<std::uint8_t>(frame + bytes.size(), kCrcSize));
        crc_field.u32(crc32(std::span<const std::uint8_t>(frame, bytes.size())));
        std::uint8_t wire[kMaxWireFrame];
        const std::size_t n = encode_for_wire(std::span<const std::uint8_t>(frame, bytes.size() + kCrcSize), wire);
        check(n > 0);
        for (std::size_t i = 0; i < n; ++i) send(wire[i]);
        break;
      }
      case RecordKind::kRepeat:
        for (unsigned r = 0; r <= (kind >> 2); ++r) {
          for (const std::uint8_t b : bytes) send(b);
        }
        break;
    }
  }

  void send(std::uint8_t byte) {
    if (streamed_ == kMaxStreamBytes) return;  // the input's budget is spent
    ++streamed_;
    const bool delimiter = byte == 0;
    if (delimiter) snapshot();
    const bool was_synchronised = link_->dispatcher().synchronised();
    const std::uint16_t was_expected = link_->dispatcher().expected_sequence();
    const std::span<const std::uint8_t> wire = link_->receive(byte);
    count_reply(delimiter, !wire.empty());
    if (wire.empty()) {
      if (delimiter) check_unchanged();
      check(link_->dispatcher().synchronised() == was_synchronised);
      check(link_->dispatcher().expected_sequence() == was_expected);
      return;
    }
    ++replies_;
    // The reply: delimiter last, no zero before it, a valid frame.
    check(wire.back() == 0);
    std::uint8_t decoded[kMaxEncodedFrame];
    const CobsDecodeResult cobs = cobs_decode(wire.first(wire.size() - 1), decoded);
    check(cobs.status == CobsStatus::kOk);
    const Reply reply = parse_reply(std::span<const std::uint8_t>(decoded, cobs.size));
    check(reply.status.ok());
    if (reply.type == MessageType::kError) {
      ErrorReply e;
      check(decode_error(reply.payload, e));
      check(e.code != ErrorCode::kNone && e.sequence == reply.sequence);
      if (delimiter) check_unchanged();
      check(link_->dispatcher().synchronised() == was_synchronised);
      check(link_->dispatcher().expected_sequence() == was_expected);
      return;
    }
    // A success reply: only at a delimiter, in order, advancing the sequence.
    ++executed_;
    check(delimiter);
    if (was_synchronised && reply.type != MessageType::kResetAck) check(reply.sequence == was_expected);
    check(link_->dispatcher().synchronised());
    check(link_->dispatcher().expected_sequence() == static_cast<std::uint16_t>(reply.sequence + 1u));
    if (reply.type == MessageType::kStepResult) {
      firmware::StepResult<FuzzModel> r;
      check(decode_step_result<FuzzModel>(reply.payload, r));
    }
  }

  // Exactly one reply per non-empty frame: counted between delimiters.
  void count_reply(bool delimiter, bool replied) {
    if (replied) ++frame_replies_;
    if (!delimiter) {
      ++frame_bytes_;
      check(frame_replies_ <= 1);
      return;
    }
    check(frame_replies_ == (frame_bytes_ > 0 ? 1u : 0u));
    frame_bytes_ = 0;
    frame_replies_ = 0;
  }

  // The device's state a refused frame must not touch: the runtime and the
  // autonomous loop (latest record, tare offsets, held muscle state).
  void snapshot() {
    std::memcpy(&before_, runtime_, sizeof(Runtime));
    std::memcpy(&loop_before_, &link_->loop(), sizeof(Loop));
  }
  void check_unchanged() const {
    check(std::memcmp(&before_, runtime_, sizeof(Runtime)) == 0);
    check(std::memcmp(&loop_before_, &link_->loop(), sizeof(Loop)) == 0);
  }

  static void check(bool ok) {
    if (!ok) std::abort();
  }

  struct Storage {
    alignas(Runtime) unsigned char runtime[sizeof(Runtime)];
    alignas(DeviceLink<FuzzModel>) unsigned char link[sizeof(DeviceLink<FuzzModel>)];
  };
  Storage storage_;
  using Loop = std::remove_reference_t<decltype(std::declval<DeviceLink<FuzzModel>&>().loop())>;
  alignas(Runtime) unsigned char before_[sizeof(Runtime)];
  alignas(Loop) unsigned char loop_before_[sizeof(Loop)];
  Runtime* runtime_ = nullptr;
  DeviceLink<FuzzModel>* link_ = nullptr;
  std::size_t replies_ = 0;
  std::size_t executed_ = 0;
  std::size_t streamed_ = 0;       // bytes sent to the device for this input (<= kMaxStreamBytes)
  std::size_t frame_bytes_ = 0;    // non-delimiter bytes since the last delimiter
  std::size_t frame_replies_ = 0;  // replies since the last delimiter
};

}  // namespace hadynet::link::fuzz

#endif  // HADYNET_FUZZ_LINK_FUZZ_HARNESS_H_
