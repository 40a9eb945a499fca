// The input limits of the log reader (docs/input-limits.md): what a
// log may hold at most before the reader refuses it with a clear error
// instead of allocating for it. Each limit is far above what a robot log
// needs and low enough that every accepted file is parsed in bounded memory
// and time (about 8 bytes of doubles per 2 bytes of text, linear time).
#pragma once

#include <cstddef>

namespace hadynet::datalog {

// Bytes of one log file. The paper's longest log (1000 steps x 46 columns)
// is about 0.4 MiB; a 40 000-row log of 60 columns about 30 MiB.
inline constexpr std::size_t kMaxLogBytes = std::size_t{256} << 20;

// Columns of the header ('t', channels, aux). The hand has 46; a whole-body
// robot a few hundred.
inline constexpr std::size_t kMaxLogColumns = 4096;

// '# key: value' lines before the header. The writer emits about ten.
inline constexpr std::size_t kMaxMetadataLines = 4096;

// Largest magnitude of a value that a tool uses as a model signal (the
// trainer's float32 network, the firmware's f32 boundary). The format
// accepts any finite double; a value beyond this (1e30 is no physical
// measurement in any SI unit) would overflow float32 once squared, summed or
// standardised, so the tools refuse it by name (check_magnitudes) instead of
// training or predicting NaN.
inline constexpr double kMaxSignalMagnitude = 1e30;

}  // namespace hadynet::datalog
