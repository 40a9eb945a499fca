// The input format of the link fuzzer (fuzz/link_fuzzer.cc) and of its seed
// corpus (fuzz/make_link_corpus.cc). An input is a sequence of records
//
//   kind u8, length u16 LE, bytes[length]
//
// kind & 3 says what the harness sends to the device:
//   0 raw      the bytes as they are (delimiters, noise, cut frames, ...)
//   1 frame    the bytes are a decoded frame without its CRC (header and
//              payload; any version, type, length field); the harness
//              appends the CRC-32, COBS-encodes it and adds the delimiter
//   2 in-order as 1, but the harness first overwrites bytes 2..3 with the
//              sequence number the device expects
//   3 repeat   the bytes sent 1 + (kind >> 2) times, raw (long runs,
//              oversize frames)
// Kinds 1 and 2 let the fuzzer reach everything behind the CRC and the
// sequence check without having to guess them; kind 0 covers the transport.
// A record cut short by the end of the input uses what is there. The
// harness streams at most kMaxStreamBytes per input and ignores the rest:
// room for an oversize frame (512 encoded bytes) and a dozen of the largest
// frames after it, while keeping every input fast: the cost is per byte
// streamed (a repeat record could otherwise stream 130 KB; measured 1 000
// inputs/s with 8 KiB, the speed the long runs need with 3 KiB).
#ifndef HADYNET_FUZZ_LINK_FUZZ_INPUT_H_
#define HADYNET_FUZZ_LINK_FUZZ_INPUT_H_

#include <cstddef>
#include <cstdint>

namespace hadynet::link::fuzz {

enum class RecordKind : std::uint8_t { kRaw = 0, kFrame = 1, kInOrderFrame = 2, kRepeat = 3 };

inline constexpr std::size_t kRecordHeader = 3;
inline constexpr std::size_t kMaxStreamBytes = 3072;

}  // namespace hadynet::link::fuzz

#endif  // HADYNET_FUZZ_LINK_FUZZ_INPUT_H_
