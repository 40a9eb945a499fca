// A client program (the hadynet CLI, dfu-util) run as a child process
// against the testbed: started with this process's environment, so under
// umockdev-wrapper it inherits LD_PRELOAD and UMOCKDEV_DIR and sees the same
// bus; its ioctls reach this process's handler through umockdev's sockets.
// While it runs, the caller's thread keeps pumping the bus (the device's
// own work, unplugs) and runs `tick` (publishing telemetry, faults); a child
// still running at `timeout` is killed (SIGKILL) and reported as timed out.
#ifndef HADYNET_TEST_USB_HOST_CHILD_PROCESS_H_
#define HADYNET_TEST_USB_HOST_CHILD_PROCESS_H_

#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "test/usb_host/usb_testbed.h"

namespace hadynet::usb::host_testing {

struct ChildResult {
  bool started = false;    // false: spawn failed (`err` says why)
  bool timed_out = false;  // killed at the time-out
  int exit_code = -1;      // -1 if it died of a signal
  std::string out, err;    // its stdout and stderr
  double elapsed_s = 0;
  std::string describe() const;  // for failure messages: exit, time, stderr
};

// `on_stdout`, if given, sees each piece of the child's stdout as it is read
// (also kept in ChildResult::out), e.g. to time when a line appears.
ChildResult run_child(UsbTestbed& bus, const std::vector<std::string>& argv, std::chrono::milliseconds timeout,
                      const std::function<void()>& tick = {},
                      const std::function<void(const std::string& piece)>& on_stdout = {});

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_USB_HOST_CHILD_PROCESS_H_
