// The driver of bench/usb_flash.sh (a benchmark, not a test): run under
// umockdev-wrapper, it serves the simulated STM32 ROM bootloader
// (test/dfuse_sim) and the hand (hand_device.h) on the testbed and times
// real clients as child processes:
//
//   flash     `hadynet flash IMAGE` (erase, write, read back + compare,
//             leave) and `dfu-util -a 0 -s 0x08000000:leave -D IMAGE`
//             (erase, write, leave; no verify), alternately, REPS times
//             each, a fresh bootloader every run; every run's flash is
//             checked against the image (a run that does not write it is
//             an error, exit 1). Wall time of the child process (start-up,
//             enumeration and libusb included).
//   model     a signed model image of the build's model (this build's
//             `hadynet model-image`, development key) into the hand's slot
//             not in use through its DFU model interface: `hadynet flash
//             --model IMAGE` (send, read back + compare) and `dfu-util -i 4
//             -a 0 -D IMAGE` (send), alternately, REPS times each, a fresh
//             hand every run; the slot must then hold the image (sequence).
//             The hand's flash is the F405's sector table with 1 % of its
//             erase times and 1 us per programmed byte (hand_device.cc), so
//             its bwPollTimeouts are small; the real F405's are summed
//             from the same poll rule with the datasheet's times (report).
//   telemetry `hadynet monitor` reading HID telemetry from the hand:
//             latency = publish of record k (one record in flight) until
//             its line ("period ... seq k ...") is read from the child's
//             stdout; throughput = records/s with the next record published
//             as soon as the host has taken the previous one's 4 reports.
//
// Prints one `key=value` line per measurement (bench/usb_flash.sh makes
// the table):
//   flash tool=hadynet|dfu-util rep=R bytes=B seconds=S datasheet_poll_ms=P sectors=N
//   model tool=hadynet|dfu-util rep=R bytes=B seconds=S
//   latency records=N median_ms=.. p90_ms=.. max_ms=..
//   throughput records=N seconds=S
//
// Usage: usb_flash_bench [--bytes N] [--reps R] [--poll-percent P]
//                        [--records N] [--skip-telemetry]
//   --bytes: size of the pseudo-random .bin at 0x08000000 (default 346732,
//   the stm32f405 hadynet-firmware image of docs/boards.md);
//   --poll-percent: the sim's bwPollTimeout in % of the datasheet's worst
//   case (default 0: host and protocol cost only).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include "test/dfuse_sim/stm32_rom_bootloader.h"
#include "test/usb/test_bytes.h"
#include "test/usb_host/child_process.h"
#include "test/usb_host/hand_device.h"
#include "test/usb_host/model_image_files.h"
#include "test/usb_host/test_records.h"
#include "test/usb_host/usb_testbed.h"

namespace hu = hadynet::usb::host_testing;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

namespace {

constexpr std::uint8_t kHandDevnum = 2;
constexpr std::uint8_t kFirstRomDevnum = 10;  // one fresh address per run
constexpr std::size_t kReportsPerRecord = 4;  // docs/usb.md: the hand's model
constexpr std::uint8_t kHidIn = 0x83;

int fail(const std::string& what) {
  std::fprintf(stderr, "usb_flash_bench: %s\n", what.c_str());
  return 1;
}

struct Args {
  std::size_t bytes = 346732;
  int reps = 3;
  std::uint32_t poll_percent = 0;
  std::uint32_t records = 200;
  bool telemetry = true;
};

// One flash run with a fresh bootloader at `devnum`; false (and `error`) if it failed.
bool flash_once(hu::UsbTestbed& bus, std::uint8_t devnum, const Args& a, bool dfu_util, const fs::path& image_path,
                const std::vector<std::uint8_t>& image, int rep, std::string& error) {
  auto rom = std::make_shared<hu::Stm32RomBootloader>();
  rom->set_poll_timeout_percent(a.poll_percent);
  if (!bus.plug(devnum, rom)) {
    error = "plug: " + bus.error();
    return false;
  }
  const std::vector<std::string> argv =
      dfu_util ? std::vector<std::string>{DFU_UTIL_EXECUTABLE, "-d", "0483:df11", "-a", "0", "-s", "0x08000000:leave",
                                          "-D", image_path.string()}
               : std::vector<std::string>{HADYNET_CLI_EXECUTABLE, "flash", "--quiet", image_path.string()};
  const hu::ChildResult r = hu::run_child(bus, argv, 600s);
  if (!r.started || r.timed_out || r.exit_code != 0) {
    error = argv[0] + ": " + r.describe();
    return false;
  }
  bool same = false;
  std::uint64_t poll_ms = 0;
  std::size_t sectors = 0;
  bus.locked([&] {
    const auto cells = rom->flash().cells();
    same = std::equal(image.begin(), image.end(), cells.begin());
    poll_ms = rom->dfu().datasheet_poll_ms();
    sectors = rom->flash().erase_count();
  });
  if (!same) {
    error = argv[0] + " exited 0 but the flash does not hold the image";
    return false;
  }
  std::printf("flash tool=%s rep=%d bytes=%zu seconds=%.4f datasheet_poll_ms=%llu sectors=%zu\n",
              dfu_util ? "dfu-util" : "hadynet", rep, image.size(), r.elapsed_s,
              static_cast<unsigned long long>(poll_ms), sectors);
  std::fflush(stdout);
  return true;
}

// One model update into a fresh hand at `devnum`; false (and `error`) if it failed.
bool model_update_once(hu::UsbTestbed& bus, std::uint8_t devnum, bool dfu_util, const fs::path& image_path,
                       std::size_t image_bytes, std::uint32_t sequence, int rep, std::string& error) {
  auto hand = std::make_shared<hu::HandDevice>();
  if (!bus.plug(devnum, hand)) {
    error = "plug the hand: " + bus.error();
    return false;
  }
  const std::vector<std::string> argv =
      dfu_util ? std::vector<std::string>{DFU_UTIL_EXECUTABLE, "-d", "1209:0001", "-i", "4", "-a", "0", "-D",
                                          image_path.string()}
               : std::vector<std::string>{HADYNET_CLI_EXECUTABLE, "flash", "--model", image_path.string()};
  const hu::ChildResult r = hu::run_child(bus, argv, 600s);
  bus.unplug(devnum);
  if (!r.started || r.timed_out || r.exit_code != 0) {
    error = argv[0] + ": " + r.describe();
    return false;
  }
  bool written = false;
  bus.locked([&] {
    for (const auto slot : {hadynet::model_update::SlotId::kA, hadynet::model_update::SlotId::kB})
      written = written || hand->slot_status(slot).sequence == sequence;
  });
  if (!written) {
    error = argv[0] + " exited 0 but no slot holds the image";
    return false;
  }
  std::printf("model tool=%s rep=%d bytes=%zu seconds=%.4f\n", dfu_util ? "dfu-util" : "hadynet", rep, image_bytes,
              r.elapsed_s);
  std::fflush(stdout);
  return true;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t i = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

int telemetry(hu::UsbTestbed& bus, const Args& a) {
  auto hand = std::make_shared<hu::HandDevice>();
  if (!bus.plug(kHandDevnum, hand)) return fail("plug the hand: " + bus.error());
  const auto publish = [&](std::uint32_t seq) { bus.locked([&] { hand->publish(hu::finite_record(seq)); }); };
  const auto reading = [&] { return bus.has_pending(kHandDevnum, kHidIn); };
  const auto taken = [&] { return bus.packets(kHandDevnum).of(kHidIn); };

  // Phase 1 (latency): record k is published once the line of k - 1 was read.
  // Phase 2 (throughput): records a.records + 1 .. 2 a.records, each as soon
  // as the host has taken the previous set's reports.
  const std::uint32_t n = a.records;
  std::uint32_t published = 0, lines_seen = 0;
  std::vector<Clock::time_point> published_at(2 * n + 2);
  std::vector<double> latency_ms;
  Clock::time_point phase2_start{}, phase2_end{};
  std::string partial;
  const auto on_stdout = [&](const std::string& piece) {
    partial += piece;
    for (std::size_t nl; (nl = partial.find('\n')) != std::string::npos; partial.erase(0, nl + 1)) {
      unsigned period = 0, seq = 0;
      if (std::sscanf(partial.c_str(), "period %u seq %u", &period, &seq) != 2) continue;
      ++lines_seen;
      if (seq >= 1 && seq <= n) {
        latency_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - published_at[seq]).count());
      }
      if (seq == 2 * n) phase2_end = Clock::now();
    }
  };
  const auto tick = [&] {
    if (!reading()) return;
    if (published < n) {
      if (lines_seen == published) {
        published_at[++published] = Clock::now();
        publish(published);
      }
    } else if (published < 2 * n) {
      if (lines_seen < n) return;
      if (published == n) phase2_start = Clock::now();
      if (taken() == kReportsPerRecord * published) publish(++published);
    }
  };
  // --duration: long enough for both phases (each record takes ~ms here);
  // the run ends with monitor's own timer.
  const hu::ChildResult r = hu::run_child(bus, {HADYNET_CLI_EXECUTABLE, "monitor", "--duration", "8"}, 60s, tick,
                                          on_stdout);
  if (!r.started || r.timed_out || r.exit_code != 0) return fail("monitor: " + r.describe());
  if (latency_ms.size() != n || phase2_end == Clock::time_point{}) {
    return fail("monitor did not print every record (" + std::to_string(latency_ms.size()) + " of " +
                std::to_string(n) + " timed; " + std::to_string(published) + " published): " + r.describe());
  }
  std::printf("latency records=%u median_ms=%.3f p90_ms=%.3f max_ms=%.3f\n", n, percentile(latency_ms, 0.5),
              percentile(latency_ms, 0.9), percentile(latency_ms, 1.0));
  std::printf("throughput records=%u seconds=%.4f\n", n,
              std::chrono::duration<double>(phase2_end - phase2_start).count());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    const auto next = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
    const char* v = nullptr;
    if (k == "--skip-telemetry") {
      a.telemetry = false;
    } else if ((k == "--bytes" || k == "--reps" || k == "--poll-percent" || k == "--records") && (v = next())) {
      const unsigned long x = std::strtoul(v, nullptr, 10);
      if (k == "--bytes") a.bytes = x;
      if (k == "--reps") a.reps = static_cast<int>(x);
      if (k == "--poll-percent") a.poll_percent = static_cast<std::uint32_t>(x);
      if (k == "--records") a.records = static_cast<std::uint32_t>(x);
    } else {
      std::fprintf(stderr, "usage: usb_flash_bench [--bytes N] [--reps R] [--poll-percent P] [--records N] "
                           "[--skip-telemetry]\n");
      return 2;
    }
  }
  if (a.bytes == 0 || a.bytes > 1024 * 1024 || a.reps < 1 || a.records < 1) return fail("bad arguments");
  if (std::string(DFU_UTIL_EXECUTABLE).empty() || !fs::exists(DFU_UTIL_EXECUTABLE)) return fail("dfu-util not found");

  hu::UsbTestbed bus;
  if (!bus.ok()) return fail(bus.error() + " (run under umockdev-wrapper)");
  const fs::path dir = fs::temp_directory_path() / ("hadynet_usb_flash_bench_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::vector<std::uint8_t> image = hadynet::usb::test_data::pseudo_random(a.bytes, 1);
  const fs::path image_path = dir / "image.bin";
  std::ofstream(image_path, std::ios::binary)
      .write(reinterpret_cast<const char*>(image.data()), static_cast<std::streamsize>(image.size()));
  std::printf("bench bytes=%zu reps=%d poll_percent=%u\n", a.bytes, a.reps, a.poll_percent);

  int rc = 0;
  std::uint8_t devnum = kFirstRomDevnum;
  for (int rep = 1; rep <= a.reps && rc == 0; ++rep) {
    for (const bool dfu_util : {false, true}) {  // alternate: drift hits both the same
      std::string error;
      if (!flash_once(bus, devnum++, a, dfu_util, image_path, image, rep, error)) {
        rc = fail(error);
        break;
      }
    }
  }
  if (rc == 0) {
    constexpr std::uint32_t kSequence = 2;
    const fs::path model_image = hu::make_model_image(bus, dir, kSequence);
    if (model_image.empty()) rc = fail("hadynet model-image failed");
    const std::size_t model_bytes = rc == 0 ? fs::file_size(model_image) : 0;
    std::uint8_t hand_devnum = kFirstRomDevnum + static_cast<std::uint8_t>(2 * a.reps);
    for (int rep = 1; rep <= a.reps && rc == 0; ++rep) {
      for (const bool dfu_util : {false, true}) {
        std::string error;
        if (!model_update_once(bus, hand_devnum++, dfu_util, model_image, model_bytes, kSequence, rep, error)) {
          rc = fail(error);
          break;
        }
      }
    }
  }
  if (rc == 0 && a.telemetry) rc = telemetry(bus, a);
  fs::remove_all(dir);
  std::printf("end\n");
  return rc;
}
