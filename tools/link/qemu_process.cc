#include "tools/link/qemu_process.h"

#include <cerrno>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace hadynet::tools {

namespace {

// A free local TCP port (the kernel's choice; released right away, so
// another process could take it first — QEMU then fails and we say so).
int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) throw LinkError(std::string("socket: ") + std::strerror(errno));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  socklen_t len = sizeof a;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
    ::close(fd);
    throw LinkError(std::string("cannot find a free port: ") + std::strerror(errno));
  }
  ::close(fd);
  return ntohs(a.sin_port);
}

}  // namespace

std::optional<QemuOptions::Load> parse_qemu_load(const std::string& spec) {
  const std::size_t at = spec.rfind('@');
  if (at == std::string::npos || at == 0 || at + 1 == spec.size()) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const unsigned long long address = std::strtoull(spec.c_str() + at + 1, &end, 0);
  if (errno != 0 || end == nullptr || *end != '\0' || address > 0xFFFFFFFFull) return std::nullopt;
  return QemuOptions::Load{spec.substr(0, at), static_cast<std::uint32_t>(address)};
}

QemuProcess::QemuProcess(const QemuOptions& o, int connect_timeout_ms) {
  struct stat st{};
  if (::stat(o.image.c_str(), &st) != 0) throw LinkError(o.image + ": no firmware image there (build the boards)");
  const int port = free_port();
  std::vector<std::string> args = {o.executable,
                                   "-M",
                                   o.machine,
                                   "-nographic",
                                   "-monitor",
                                   "none",
                                   "-semihosting-config",
                                   "enable=on,target=native",
                                   "-kernel",
                                   o.image,
                                   "-chardev",
                                   "socket,id=link,host=127.0.0.1,port=" + std::to_string(port) + ",server=on,wait=on",
                                   "-serial",
                                   "chardev:link"};
  if (o.icount) {
    args.push_back("-icount");
    args.push_back("shift=0");
  }
  for (const QemuOptions::Load& load : o.loads) {
    if (::stat(load.file.c_str(), &st) != 0) throw LinkError(load.file + ": no such file to load into the guest");
    args.push_back("-device");
    args.push_back("loader,file=" + load.file + ",addr=" + std::to_string(load.address) + ",force-raw=on");
  }
  pid_ = ::fork();
  if (pid_ < 0) throw LinkError(std::string("fork: ") + std::strerror(errno));
  if (pid_ == 0) {
    const int out = ::open(o.log_file.empty() ? "/dev/null" : o.log_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (out >= 0) {
      ::dup2(out, STDOUT_FILENO);
      ::dup2(out, STDERR_FILENO);
    }
    const int in = ::open("/dev/null", O_RDONLY);
    if (in >= 0) ::dup2(in, STDIN_FILENO);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execvp(argv[0], argv.data());
    ::_exit(127);
  }
  try {
    link_ = std::make_unique<FdStream>(FdStream::connect_tcp("127.0.0.1", port, connect_timeout_ms));
  } catch (const LinkError& e) {
    int status = 0;
    const bool exited = ::waitpid(pid_, &status, WNOHANG) == pid_;
    if (!exited) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, &status, 0);
    }
    pid_ = -1;
    throw LinkError(std::string("QEMU (") + o.executable + " -M " + o.machine + ") " +
                    (exited ? "exited before the link came up" : "did not open its serial socket") + ": " + e.what() +
                    (o.log_file.empty() ? "" : " (QEMU's output: " + o.log_file + ")"));
  }
}

QemuProcess::~QemuProcess() {
  link_.reset();
  if (pid_ > 0) {
    ::kill(pid_, SIGTERM);
    int status = 0;
    for (int i = 0; i < 100; ++i) {
      if (::waitpid(pid_, &status, WNOHANG) == pid_) return;
      ::usleep(10000);
    }
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, &status, 0);
  }
}

}  // namespace hadynet::tools
