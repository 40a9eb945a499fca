// libFuzzer target for the log reader (datalog/log_reader.h): any bytes give
// either a table that keeps every promise of docs/log-format.md, or a
// LogError. Anything else (another exception, a crash, a sanitizer report,
// an allocation past -rss_limit_mb) is a finding. An accepted table must
// also survive the writer and read back identical.
//   build/release/fuzz/log_fuzzer -max_len=4096 WORKDIR fuzz/corpus/log
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "datalog/dataset_manifest.h"
#include "datalog/log_limits.h"
#include "datalog/log_reader.h"
#include "datalog/log_writer.h"

namespace {

void require(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hadynet::datalog;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  LogTable table;
  try {
    table = parse_log(text, "fuzz.csv");
  } catch (const LogError& e) {
    require(e.what()[0] != '\0');
    return 0;
  }
  // Promises of an accepted log.
  require(!table.columns.empty() && table.columns.size() <= kMaxLogColumns);
  require(table.metadata.entries().size() <= kMaxMetadataLines);
  require(table.rows() >= 1 && table.values.size() == table.rows() * table.columns.size());
  for (const double v : table.values) require(std::isfinite(v));
  const ChannelLayout layout = channel_layout(table, "fuzz.csv");
  require(layout.time_column < table.columns.size() && !layout.observed.empty());
  // Written and read back: the same table.
  const std::string again = format_log(table, "fuzz.csv");
  const LogTable back = parse_log(again, "fuzz.csv");
  require(back.columns == table.columns && back.values == table.values &&
          back.metadata.entries() == table.metadata.entries());
  return 0;
}
