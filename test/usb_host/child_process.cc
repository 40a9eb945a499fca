#include "test/usb_host/child_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <thread>

extern char** environ;

namespace hadynet::usb::host_testing {
namespace {

// Everything readable now from a non-blocking pipe; false at end of file.
bool drain(int fd, std::string& into) {
  char buffer[4096];
  while (true) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n > 0) {
      into.append(buffer, static_cast<std::size_t>(n));
      continue;
    }
    return n < 0 && (errno == EAGAIN || errno == EINTR);
  }
}

}  // namespace

std::string ChildResult::describe() const {
  std::string s = !started ? "not started" : timed_out ? "TIMED OUT (killed)" : "exit " + std::to_string(exit_code);
  s += " after " + std::to_string(elapsed_s) + " s\n--- stdout:\n" + out + "--- stderr:\n" + err;
  return s;
}

ChildResult run_child(UsbTestbed& bus, const std::vector<std::string>& argv, std::chrono::milliseconds timeout,
                      const std::function<void()>& tick,
                      const std::function<void(const std::string& piece)>& on_stdout) {
  ChildResult r;
  int out_pipe[2], err_pipe[2];
  if (::pipe2(out_pipe, O_CLOEXEC) != 0 || ::pipe2(err_pipe, O_CLOEXEC) != 0) {
    r.err = std::string("pipe: ") + std::strerror(errno);
    return r;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, out_pipe[1], 1);
  posix_spawn_file_actions_adddup2(&actions, err_pipe[1], 2);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const auto start = std::chrono::steady_clock::now();
  const int spawned = ::posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(out_pipe[1]);
  ::close(err_pipe[1]);
  if (spawned != 0) {
    r.err = "posix_spawn " + argv[0] + ": " + std::strerror(spawned);
    ::close(out_pipe[0]);
    ::close(err_pipe[0]);
    return r;
  }
  r.started = true;
  ::fcntl(out_pipe[0], F_SETFL, O_NONBLOCK);
  ::fcntl(err_pipe[0], F_SETFL, O_NONBLOCK);
  int status = 0;
  while (true) {
    bus.pump();
    if (tick) tick();
    const std::size_t out_before = r.out.size();
    drain(out_pipe[0], r.out);
    if (on_stdout && r.out.size() > out_before) on_stdout(r.out.substr(out_before));
    drain(err_pipe[0], r.err);
    const pid_t w = ::waitpid(pid, &status, WNOHANG);
    if (w == pid) break;
    if (std::chrono::steady_clock::now() - start > timeout) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      r.timed_out = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  for (int i = 0; i < 100 && (drain(out_pipe[0], r.out) || drain(err_pipe[0], r.err)); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));  // a grandchild may hold the pipes; bounded
  }
  ::close(out_pipe[0]);
  ::close(err_pipe[0]);
  r.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!r.timed_out && WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  bus.pump();  // what the child's exit left (vanished clients, a device that left)
  return r;
}

}  // namespace hadynet::usb::host_testing
