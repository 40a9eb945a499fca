#include "datalog/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <string>
#include <system_error>

namespace hadynet::datalog {

namespace {

// Distinguishes the temporary files of concurrent writers in one process.
std::atomic<unsigned long> temporary_counter{0};

// Removes the temporary file unless released (after the rename).
class TemporaryFile {
 public:
  explicit TemporaryFile(std::filesystem::path path) : path_(std::move(path)) {}
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  ~TemporaryFile() {
    if (!path_.empty()) ::unlink(path_.c_str());
  }
  void release() { path_.clear(); }

 private:
  std::filesystem::path path_;
};

AtomicWriteError failure(const std::string& what, int error) {
  return AtomicWriteError(what + ": " + std::generic_category().message(error));
}

}  // namespace

void write_file_atomically(const std::filesystem::path& path, std::string_view bytes,
                           const AtomicWriteOptions& options) {
  if (!path.has_filename()) throw AtomicWriteError(path.string() + ": no file name");
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");

  int fd = -1;
  std::filesystem::path temporary_path;
  for (int attempt = 0; fd < 0; ++attempt) {
    temporary_path = folder / ("." + path.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                               std::to_string(temporary_counter.fetch_add(1)));
    fd = ::open(temporary_path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, static_cast<mode_t>(options.mode));
    const int error = errno;
    if (fd < 0 && (error != EEXIST || attempt >= 100)) throw failure("create temporary file " + temporary_path.string(), error);
  }
  TemporaryFile temporary(temporary_path);

  std::size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0) {
      const int error = errno;
      if (error == EINTR) continue;
      ::close(fd);
      throw failure("write " + temporary_path.string(), error);
    }
    written += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const int error = errno;
    ::close(fd);
    throw failure("fsync " + temporary_path.string(), error);
  }
  if (::close(fd) != 0) throw failure("close " + temporary_path.string(), errno);
  if (options.replace) {
    if (::rename(temporary_path.c_str(), path.c_str()) != 0)
      throw failure("rename " + temporary_path.string() + " to " + path.string(), errno);
    temporary.release();
  } else {
    // link() never replaces: an existing PATH fails with EEXIST. The
    // temporary name is removed by `temporary` either way.
    if (::link(temporary_path.c_str(), path.c_str()) != 0)
      throw failure("create " + path.string(), errno);
  }

  const int folder_fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (folder_fd >= 0) {
    ::fsync(folder_fd);
    ::close(folder_fd);
  }
}

}  // namespace hadynet::datalog
