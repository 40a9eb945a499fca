#include "datalog/log_writer.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <system_error>

#include "datalog/log_reader.h"
#include "datalog/log_rules.h"

namespace hadynet::datalog {
namespace {

void check_metadata_entries(const LogMetadata& metadata, const std::string& file) {
  const auto& entries = metadata.entries();
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto& [key, value] = entries[i];
    rules::check_metadata_key(key, file, i + 1);
    if (value.find_first_of("\r\n") != std::string::npos) {
      throw LogError(file, i + 1, 0, "",
                     "metadata " + rules::quoted(key) +
                         ": value holds a line break; expected a single line");
    }
  }
}

}  // namespace

std::string format_log(const LogTable& table, const std::string& file_for_errors) {
  const std::string& file = file_for_errors;
  check_metadata_entries(table.metadata, file);
  const double dt_s = rules::check_required_metadata(table.metadata, file);
  const ChannelLayout layout = channel_layout(table, file);

  const std::size_t columns = table.columns.size();
  const std::size_t header_line = rules::header_line(table);
  if (table.values.size() % columns != 0) {
    throw LogError(file, 0, 0, "",
                   "table holds " + std::to_string(table.values.size()) +
                       " values; expected a multiple of the " + std::to_string(columns) +
                       " columns");
  }
  const std::size_t rows = table.rows();
  if (rows == 0) {
    throw LogError(file, 0, 0, "",
                   "no data rows after the header (line " + std::to_string(header_line) +
                       "); expected at least one");
  }

  std::string out;
  out.reserve(64 * table.metadata.entries().size() + 8 * columns + 16 * table.values.size());
  for (const auto& [key, value] : table.metadata.entries()) {
    out += "# ";
    out += key;
    out += ':';
    if (!value.empty()) {
      out += ' ';
      out += value;
    }
    out += '\n';
  }
  for (std::size_t c = 0; c < columns; ++c) {
    if (c > 0) out += ',';
    out += table.columns[c];
  }
  out += '\n';
  // Metadata values and aux_ names are free text: the reader wants UTF-8.
  if (const std::size_t bad = rules::first_invalid_utf8(out); bad != std::string::npos) {
    const auto before = std::string_view(out).substr(0, bad);
    const auto line = static_cast<std::size_t>(std::count(before.begin(), before.end(), '\n')) + 1;
    throw LogError(file, line, 0, "", rules::invalid_utf8_message(out, bad));
  }

  for (std::size_t r = 0; r < rows; ++r) {
    const std::size_t line = header_line + 1 + r;
    for (std::size_t c = 0; c < columns; ++c) {
      const double value = table.at(r, c);
      if (!std::isfinite(value)) {
        throw LogError(file, line, c + 1, table.columns[c],
                       "not written: the value to write is " + rules::format_number(value) +
                           ", and a log holds finite numbers only (the computation that produced it "
                           "failed)");
      }
      if (c > 0) out += ',';
      rules::append_number(out, value);
    }
    out += '\n';
    if (r > 0) {
      rules::check_time_step(table.at(r - 1, layout.time_column), table.at(r, layout.time_column),
                             dt_s, file, line, layout.time_column + 1);
    }
  }
  return out;
}

namespace {

// Removes the temporary file unless release()d.
class TemporaryFile {
 public:
  explicit TemporaryFile(std::filesystem::path path) : path_(std::move(path)) {}
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  ~TemporaryFile() {
    if (!released_) ::unlink(path_.c_str());
  }
  void release() { released_ = true; }

 private:
  std::filesystem::path path_;
  bool released_ = false;
};

std::atomic<unsigned> temporary_counter{0};

}  // namespace

void write_log(const std::filesystem::path& path, const LogTable& table) {
  const std::string file = path.string();
  const std::string text = format_log(table, file);
  const auto fail = [&](std::string_view what, int error) {
    return LogError(file, 0, 0, "",
                    "cannot write log file: " + std::string(what) + ": " +
                        std::generic_category().message(error));
  };

  if (!path.has_filename()) throw LogError(file, 0, 0, "", "cannot write log file: no file name");
  const std::filesystem::path folder =
      path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");

  // A name no other writer uses: hidden, same folder (rename stays atomic),
  // process id plus a per-process counter; O_EXCL guards against leftovers.
  int fd = -1;
  std::filesystem::path temporary_path;
  for (int attempt = 0; fd < 0; ++attempt) {
    std::string name(1, '.');
    name += path.filename().string();
    name += ".tmp-";
    name += std::to_string(::getpid());
    name += '-';
    name += std::to_string(temporary_counter.fetch_add(1));
    temporary_path = folder / name;
    fd = ::open(temporary_path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    const int error = errno;
    if (fd < 0 && (error != EEXIST || attempt >= 100)) {
      throw fail("create temporary file " + temporary_path.string(), error);
    }
  }
  TemporaryFile temporary(temporary_path);

  std::size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
    if (n < 0) {
      const int error = errno;
      if (error == EINTR) continue;
      ::close(fd);
      throw fail("write " + temporary_path.string(), error);
    }
    written += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const int error = errno;
    ::close(fd);
    throw fail("fsync " + temporary_path.string(), error);
  }
  if (::close(fd) != 0) {
    const int error = errno;
    throw fail("close " + temporary_path.string(), error);
  }
  if (::rename(temporary_path.c_str(), path.c_str()) != 0) {
    const int error = errno;
    throw fail("rename " + temporary_path.string() + " to " + file, error);
  }
  temporary.release();

  // Make the rename itself durable. Best effort: the file is already complete
  // under its final name, so a failure here is not reported.
  const int folder_fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (folder_fd >= 0) {
    ::fsync(folder_fd);
    ::close(folder_fd);
  }
}

}  // namespace hadynet::datalog
