// The one way host tools write a file they must not leave half-written (logs,
// models, generated headers, manifests): the bytes go to a hidden temporary
// file in the same folder (".NAME.tmp-PID-N", created with O_EXCL), which is
// fsync'ed, closed and renamed onto PATH (atomic on POSIX); then the folder
// is fsync'ed so that the rename survives a power cut (best effort: the file
// is already complete under its name). On any failure the temporary file is
// removed and PATH is untouched: it holds either its old content or none.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string_view>

namespace hadynet::datalog {

// what(): the step that failed, the file and the system's reason, e.g.
// "create temporary file out/.x.tmp-12-0: Permission denied".
class AtomicWriteError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct AtomicWriteOptions {
  unsigned mode = 0666;  // permissions the file is created with (less the umask), before any byte is written
  bool replace = true;   // false: an existing PATH is an error (EEXIST) and stays as it is
};

// Replaces PATH by `bytes` (or, with replace false, creates it), atomically
// and durably. The folder must exist. Throws AtomicWriteError.
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes,
                           const AtomicWriteOptions& options = {});

}  // namespace hadynet::datalog
