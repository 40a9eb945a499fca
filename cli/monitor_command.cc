// hadynet monitor: the firmware's HID telemetry, live (hidapi's libusb
// backend): one line per control period, drops counted from the sequence
// numbers, the stream written as HADYNET logs (tools/usb/telemetry_log.h)
// and drawn as a PNG; Ctrl-C (or --duration) ends it with a summary.
#include <csignal>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/gnuplot.h"
#include "cli/options.h"
#include "datalog/log_writer.h"
#include "firmware/usb/telemetry_decoder.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "tools/usb/hid_telemetry_reader.h"
#include "tools/usb/telemetry_log.h"

namespace hadynet::cli {
namespace fs = std::filesystem;

namespace {

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_interrupt(int) { g_stop = 1; }

constexpr int kReadTimeoutMs = 200;     // the stop flag and the duration are checked this often
constexpr double kSilenceWarnS = 2.0;   // no report for this long: say so (once per silence)

const char* mode_word(firmware::Mode m) {
  switch (m) {
    case firmware::Mode::kObserve: return "observe";
    case firmware::Mode::kDetect: return "detect";
    case firmware::Mode::kControl: return "control";
  }
  return "?";
}

template <class M>
void print_line(const app::PeriodRecord<M>& r) {
  std::string flags;
  const auto add = [&](std::uint16_t bit, const char* word) {
    if (!r.has(bit)) return;
    if (!flags.empty()) flags += ",";
    flags += word;
  };
  add(app::kRecordStaleMuscleState, "stale");
  add(app::kRecordNoMuscleState, "no-muscle-state");
  add(app::kRecordNoLoadcells, "no-loadcells");
  add(app::kRecordOverrun, "overrun");
  double norm = 0;
  for (int i = 0; i < M::kU; ++i) norm += static_cast<double>(r.command[i]) * r.command[i];
  // The on-device recognition: the adapted PB's nearest trained state,
  // its distance and the nearest other object's (docs/firmware.md).
  std::string object;
  if (r.has(app::kRecordRecognition)) {
    char text[160];
    if (r.other_object_state == app::kRecordNoOtherObject) {
      std::snprintf(text, sizeof text, "  object %s %.2f", M::kStateNames[r.recognized_state],
                    static_cast<double>(r.recognized_distance));
    } else {
      std::snprintf(text, sizeof text, "  object %s %.2f (next %s %.2f)", M::kStateNames[r.recognized_state],
                    static_cast<double>(r.recognized_distance), M::kStateNames[r.other_object_state],
                    static_cast<double>(r.other_object_distance));
    }
    object = text;
  }
  std::printf("period %8u  seq %8u  %-7s  d %s  contact %-3s  |u| %s  %s%s\n", r.period, r.sequence, mode_word(r.mode),
              r.has(app::kRecordDistanceValid) ? (std::to_string(r.d).substr(0, 8)).c_str() : "   -    ",
              r.has(app::kRecordContact) ? "yes" : "no",
              r.has(app::kRecordCommandValid) ? std::to_string(std::sqrt(norm)).substr(0, 7).c_str() : "   -   ",
              flags.empty() ? "ok" : flags.c_str(), object.c_str());
  std::fflush(stdout);
}

// OUT for the first segment, OUT's stem + "-<k>" + extension for segment k.
fs::path segment_path(const fs::path& out, std::size_t k) {
  if (k == 1) return out;
  return out.parent_path() / (out.stem().string() + "-" + std::to_string(k) + out.extension().string());
}

template <class M>
std::string plot(const std::vector<datalog::LogTable>& segments, const fs::path& png, const std::string& title) {
  std::string s = "$d << EOD\n";
  for (const auto& seg : segments) {
    const std::size_t t = *seg.column_index("t"), d = *seg.column_index("aux_d"),
                      contact = *seg.column_index("aux_contact"), flags = *seg.column_index("aux_flags");
    for (std::size_t r = 0; r < seg.rows(); ++r) {
      const bool valid = (static_cast<unsigned>(seg.at(r, flags)) & app::kRecordDistanceValid) != 0;
      char line[96];
      std::snprintf(line, sizeof line, "%.9g %s %g\n", seg.at(r, t), valid ? std::to_string(seg.at(r, d)).c_str() : "NaN",
                    seg.at(r, contact));
      s += line;
    }
    s += "\n";  // a blank line: gnuplot does not join segments across a gap
  }
  s += "EOD\n";
  s += "set terminal pngcairo size 1200,500 font 'sans,9' noenhanced\n";
  s += "set output " + gnuplot_quote(png.string()) + "\n";
  s += "set title " + gnuplot_quote(title) + "\nset grid\nset xlabel 't [s] (period x 0.2 s)'\n";
  s += "set ylabel 'd (standardised)'\nset key top left\n";
  s += "plot $d using 1:2 with lines lw 1 title 'd', $d using 1:($3 > 0 ? $2 : NaN) with points pt 7 ps 0.6 "
       "title 'contact'\n";
  return run_gnuplot(s, png.string());
}

template <class M>
int monitor(const Options& opt, double duration_s) {
  tools::usb::HidTelemetryReader reader(opt.get("serial"));
  std::fprintf(stderr, "hadynet monitor: hand %s, telemetry; Ctrl-C ends\n", reader.serial().c_str());
  usb::TelemetryDecoder<M> decoder;
  tools::usb::TelemetryLog<M> log("hadynet monitor, hand " + reader.serial());
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
  const auto start = std::chrono::steady_clock::now();
  auto last_report = start;
  bool warned_silence = false;
  std::uint8_t report[64];
  std::string failure;
  while (g_stop == 0) {
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start).count();
    if (duration_s > 0 && elapsed >= duration_s) break;
    std::size_t n = 0;
    try {
      n = reader.read(report, kReadTimeoutMs);
    } catch (const std::exception& e) {
      failure = e.what();
      break;
    }
    if (n == 0) {
      if (!warned_silence && std::chrono::duration<double>(now - last_report).count() > kSilenceWarnS) {
        std::fprintf(stderr, "hadynet monitor: no telemetry for %.0f s (is the loop running? it reports each period)\n",
                     kSilenceWarnS);
        warned_silence = true;
      }
      continue;
    }
    last_report = std::chrono::steady_clock::now();
    warned_silence = false;
    if (decoder.push(std::span<const std::uint8_t>(report, n)) != usb::TelemetryDecoder<M>::Event::kRecord) continue;
    const app::PeriodRecord<M>& r = decoder.record();
    if (!opt.has("quiet")) print_line<M>(r);
    log.add(r);
  }
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);

  const usb::TelemetryStats& st = decoder.stats();
  std::fprintf(stderr,
               "hadynet monitor: %llu periods received, %llu dropped (sequence gaps), %llu malformed reports, "
               "%llu incomplete report sets, %llu undecodable sets, %llu duplicates, %llu restarts\n",
               static_cast<unsigned long long>(st.records), static_cast<unsigned long long>(st.dropped),
               static_cast<unsigned long long>(st.bad_reports), static_cast<unsigned long long>(st.incomplete_sets),
               static_cast<unsigned long long>(st.bad_payloads), static_cast<unsigned long long>(st.duplicates),
               static_cast<unsigned long long>(st.restarts));
  if (log.skipped_records() > 0) {
    std::fprintf(stderr, "hadynet monitor: %llu records held a non-finite value and are not in the logs\n",
                 static_cast<unsigned long long>(log.skipped_records()));
  }
  int status = failure.empty() ? 0 : 1;
  if (opt.has("csv") && !log.segments().empty()) {
    const fs::path out = opt.get("csv");
    for (std::size_t k = 1; k <= log.segments().size(); ++k) {
      datalog::write_log(segment_path(out, k), log.segments()[k - 1]);
      std::fprintf(stderr, "hadynet monitor: wrote %s (%zu periods)\n", segment_path(out, k).c_str(),
                   log.segments()[k - 1].rows());
    }
    if (log.segments().size() > 1) {
      std::fprintf(stderr, "hadynet monitor: %zu logs: the stream had gaps (a log's time axis must be regular)\n",
                   log.segments().size());
    }
  }
  if (opt.has("plot") && !log.segments().empty()) {
    const std::string err = plot<M>(log.segments(), opt.get("plot"), "hand " + reader.serial() + ": contact distance");
    if (!err.empty()) {
      std::fprintf(stderr, "hadynet monitor: %s\n", err.c_str());
      status = 1;
    } else {
      std::fprintf(stderr, "hadynet monitor: wrote %s\n", opt.get("plot").c_str());
    }
  }
  if (!failure.empty()) std::fprintf(stderr, "hadynet monitor: %s\n", failure.c_str());
  return status;
}

}  // namespace

int run_monitor(int argc, char** argv) {
  Options opt("monitor",
              "Reads the firmware's HID telemetry over USB (hidapi, libusb backend): prints one line per\n"
              "control period (period, sequence, mode, d, contact, |u|, flags: stale/no-muscle-state/\n"
              "no-loadcells/overrun; with on-device PB adaptation the recognised object and the nearest\n"
              "other one with their distances), counts dropped periods from the sequence numbers, and ends\n"
              "on Ctrl-C or after --duration with a summary. --csv writes the stream as HADYNET logs\n"
              "(loadcells, aux_d, aux_contact, aux_mode, aux_flags, aux_pred_*, aux_cmd_*, aux_adapt_updates,\n"
              "aux_recognized_state, aux_recognized_distance, aux_other_object_state (-1: none),\n"
              "aux_other_object_distance); a gap in the stream starts a new log (OUT-2.csv, ...), since a\n"
              "log's time axis is regular.",
              "[--serial S] [--csv OUT] [--plot PNG] [--duration S]");
  opt.value("serial", "S", "the hand's serial number (see hadynet devices); needed if several are attached");
  opt.value("csv", "OUT", "write the stream as HADYNET log(s)");
  opt.value("plot", "PNG", "draw d over time with the contacts marked (gnuplot)");
  opt.value("duration", "S", "stop after S seconds (0: until Ctrl-C)", "0");
  opt.value("numeric", "q15|f32", "the device's numeric (report sizes come from this build's model)", "q15");
  opt.flag("quiet", "no line per period (the summary and files only)");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (!opt.positional().empty()) {
    std::fprintf(stderr, "hadynet monitor: takes no positional arguments (see --help)\n");
    return 2;
  }
  const auto duration = opt.get_double("duration", 0, 1e7);
  if (!duration) return 2;
  const auto parsed_numeric = opt.get_numeric("numeric");
  if (!parsed_numeric) return 2;
  try {
    return *parsed_numeric == firmware::Numeric::kQ15 ? monitor<model_q15::Model>(opt, *duration) : monitor<model_f32::Model>(opt, *duration);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hadynet monitor: %s\n", error_text(e).c_str());
    return 1;
  }
}

}  // namespace hadynet::cli
