// The USB benchmark image (not a test; bench/usb_icount.sh, docs/usb.md
// "Benchmark"): what the USB device stack (firmware/usb/) adds to each
// control period, next to the period's own runtime work, counted in
// SysTick cycles under QEMU `-icount shift=0` (mps2-an386: 1 tick = 40
// instructions; bench.h).
//
// The firmware's main loop (firmware_main.cc with usb_link.cc) with the q15
// runtime, a link::DeviceLink and the composite HadynetUsbDevice over the
// host backend of the controller seam (FakeController), whose host side
// plays the USB host on the same core. After enumeration (bus reset,
// SET_ADDRESS, SET_CONFIGURATION, SET_CONTROL_LINE_STATE) and a link
// session start over CDC (reset, set mode), each period k does:
//
//   host    muscle state k (SyntheticFrames; loadcells dropped) as a link
//           frame (LinkClient: untimed host work) -> bulk OUT 0x02, 64-byte
//           packets; the device calls usb.service() after each packet
//           (CDC bytes -> DeviceLink -> 0x86 ack -> bulk IN)
//   host    reads the ack from bulk IN 0x82 until NAK; usb.service()
//   device  board::read_loadcells (synthetic, untimed), loop.run_period,
//           loop.end_period                                 (the baseline)
//   device  usb.publish(loop.latest())
//   host    reads the HID report set from interrupt IN 0x83 until NAK;
//           usb.service()
//
// kWarmup untimed periods in detect mode (the detector's history), then
// kPeriods timed ones; set mode control, one untimed period (it takes the
// reference), kPeriods timed ones. Every reply and every record is checked
// (sequence, fresh muscle state, stepped); any failure prints
// `error <what>` and exits 1.
//
// Output (one line each, then exit 0):
//   bench board=<name> numeric=q15 tick_hz=<Hz> model=<hash> periods=<timed periods per mode>
//   job name=<job> reps=<n> ticks=<SysTick cycles, all reps> timings=<ticks() pairs, all reps>
//   check ...                     (what the host received)
//   memory stack_used=<bytes> stack=<bytes> usb_device=<sizeof> ... (bytes)
//   end
// Jobs (ticks include `timings` x the cost of one empty pair, job ticks_overhead):
//   period_detect   run_period + end_period of a detect-mode period (reps = kPeriods)
//   period_control  the same in control mode (default settings)
//   usb_service     all usb.service() calls of a period (4: CDC bytes through the
//                   link, OUT re-arm, IN start); includes the job `link`
//   usb_publish     usb.publish(): the record as 4 reports, first IN transfer started
//   usb_events      UsbDevice::handle() of each controller event the host's tokens
//                   raised (2 OUT + 1 IN completion of CDC, 4 of HID: 7 per period)
//   link            the same frame bytes into a twin DeviceLink on its own
//                   runtime: the link's share of usb_service (the UART pays it too)
//   host            the fake controller's host side (tokens, packet copies),
//                   nested events excluded: simulation, NOT firmware work
//   service_idle    one usb.service() with nothing to do (reps = calls): the
//                   cost of every further main-loop pass
//   ticks_overhead  an empty t0/t1 pair (reps = timings = pairs)
// The stack's calls into the controller (start_transfer, ...) run the fake's
// device-side bookkeeping, in place of the OTG FS driver's register and FIFO
// writes, and count in the job that made them; they pass through
// EventTimingController (one forwarding virtual call each).
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <type_traits>

#include "boards/board.h"
#include "firmware/app/channel_layout.h"
#include "firmware/app/image_checks.h"
#include "firmware/app/period_loop.h"
#include "firmware/app/synthetic_frames.h"
#include "firmware/app/text.h"
#include "firmware/core/hadynet_runtime.h"
#include "firmware/link/device_link.h"
#include "firmware/link/frame.h"
#include "firmware/link/link_client.h"
#include "firmware/link/messages.h"
#include "firmware/link/stream_decoder.h"
#include "firmware/usb/composite_descriptors.h"
#include "firmware/usb/device_controller.h"
#include "firmware/usb/hadynet_usb_device.h"
#include "firmware/usb/host/fake_controller.h"
#include "firmware/usb/telemetry_decoder.h"
#include "hadynet_model_q15.h"

namespace {

namespace board = hadynet::board;
namespace usb = hadynet::usb;
namespace link = hadynet::link;
namespace app = hadynet::app;
namespace firmware = hadynet::firmware;

using Model = hadynet::model_q15::Model;
using Runtime = firmware::HadynetRuntime<Model>;
using DeviceLink = link::DeviceLink<Model>;
using Usb = usb::HadynetUsbDevice<Model, DeviceLink, link::kMaxWireFrame>;
using Loop = app::PeriodLoop<Model>;
using usb::host::FakeController;
using usb::host::Handshake;

static_assert(app::model_fits_board<Model>());  // board reading k is the model's loadcell k

constexpr int kPeriods = 50;                     // timed periods per mode
constexpr int kWarmup = Model::kDetectSteps + 2;  // untimed detect periods first (bench.h)
constexpr int kIdleCalls = 1000;
constexpr int kOverheadPairs = 1000;

// SysTick cycles and the number of t0/t1 pairs that measured them.
struct Job {
  std::uint32_t ticks = 0;
  std::uint32_t timings = 0;
};

// Every job of the timed periods (reported as described at the top).
struct Jobs {
  Job period_detect, period_control, service, publish, events, link, host;
};
Jobs g_jobs;

// Runs f() between two board::ticks() readings, adding the difference to `job`.
template <class F>
auto timed(Job& job, F&& f) noexcept {
  const std::uint32_t t0 = board::ticks();
  if constexpr (std::is_void_v<decltype(f())>) {
    f();
    job.ticks += board::ticks() - t0;
    ++job.timings;
  } else {
    const auto r = f();
    job.ticks += board::ticks() - t0;
    ++job.timings;
    return r;
  }
}

// The controller seam between the stack and the fake: forwards every call,
// and times each event the fake delivers (the stack's UsbDevice::handle(),
// job `events`), so that the fake's host-side work can be told apart from
// the stack's.
class EventTimingController final : public usb::DeviceController, usb::ControllerEventHandler {
 public:
  explicit EventTimingController(FakeController& fake) noexcept : fake_(fake) {}

  void init(usb::ControllerEventHandler& handler) noexcept override {
    device_ = &handler;
    fake_.init(*this);
  }
  void set_connected(bool connected) noexcept override { fake_.set_connected(connected); }
  void set_address(std::uint8_t address) noexcept override { fake_.set_address(address); }
  bool open_endpoint(const usb::EndpointConfig& config) noexcept override { return fake_.open_endpoint(config); }
  void close_endpoint(usb::EndpointAddress ep) noexcept override { fake_.close_endpoint(ep); }
  bool start_transfer(usb::EndpointAddress ep, std::span<std::uint8_t> buffer) noexcept override {
    return fake_.start_transfer(ep, buffer);
  }
  void stall_control() noexcept override { fake_.stall_control(); }
  void set_endpoint_halt(usb::EndpointAddress ep, bool halted) noexcept override {
    fake_.set_endpoint_halt(ep, halted);
  }

  // Events (the fake calls this from its host-side calls).
  void handle(const usb::ControllerEvent& event) noexcept override {
    timed(g_jobs.events, [&] { device_->handle(event); });
  }

 private:
  FakeController& fake_;
  usb::ControllerEventHandler* device_ = nullptr;
};

// ---- the device (all static: no heap) ----
// DFU mode without model slots (as on a board without model flash): it is
// idle during the benchmark, and the model slots are the application's
// (ModelSlots), not the USB stack's.
struct NoDetach final : usb::DetachHook {
  void detach_to_bootloader(std::uint16_t) noexcept override {}
};
NoDetach g_detach;
constexpr std::array<std::uint8_t, usb::kUniqueIdBytes> kUid = {0x42, 0x45, 0x4E, 0x43, 0x48, 0x55,
                                                                 0x53, 0x42, 0x00, 0x00, 0x00, 0x01};

Runtime g_runtime;
DeviceLink g_link(g_runtime);
FakeController g_fake;
EventTimingController g_controller(g_fake);
Usb g_usb(g_controller, g_link, usb::ModelSlotsAccess{}, g_detach, kUid, "bench");

// ---- the twin link (the `link` job) and the host's state ----
Runtime g_twin_runtime;
DeviceLink g_twin(g_twin_runtime);
link::LinkClient<Model> g_client;
link::StreamDecoder g_replies;
usb::TelemetryDecoder<Model> g_telemetry;
std::uint8_t g_wire[link::kMaxWireFrame];

std::uint32_t g_replies_ok = 0;     // success replies the host read over CDC
std::uint32_t g_last_ack = 0;       // payload of the last 0x86 ack: the record that uses the state
// Bytes of the last period on the wire: the muscle state frame (bulk OUT),
// its ack (bulk IN), the HID report set (interrupt IN).
std::size_t g_frame_bytes = 0, g_reply_bytes = 0, g_hid_bytes = 0;
volatile std::uint32_t g_sink = 0;  // keeps the twin's replies alive

template <std::size_t N>
void emit(const app::Text<N>& text) noexcept {
  board::uart_write(text.bytes().data(), text.bytes().size());
}

[[noreturn]] void fail(std::string_view what, std::uint32_t value = 0) noexcept {
  app::Text<128> line;
  line << "error " << what << " (" << value << ")\n";
  emit(line);
  board::exit(1);
}

void report(std::string_view name, int reps, const Job& job) noexcept {
  app::Text<128> line;
  line << "job name=" << name << " reps=" << reps << " ticks=" << job.ticks << " timings=" << job.timings << '\n';
  emit(line);
}

// A host-side call of the fake, timed as `host` minus the stack's event
// handling nested inside it.
template <class F>
auto host(F&& f) noexcept {
  const Job nested = g_jobs.events;
  const std::uint32_t t0 = board::ticks();
  const auto r = f();
  const std::uint32_t t1 = board::ticks();
  g_jobs.host.ticks += (t1 - t0) - (g_jobs.events.ticks - nested.ticks);
  g_jobs.host.timings += 1 + (g_jobs.events.timings - nested.timings);  // a nested pair leaves ~one pair's cost here
  return r;
}

void service() noexcept {
  timed(g_jobs.service, [] { g_usb.service(); });
}

// Host: one control transfer without data stage; it must succeed.
void control(std::uint8_t request_type, std::uint8_t request, std::uint16_t value, std::uint16_t index) noexcept {
  const usb::SetupPacket s{request_type, request, value, index, 0};
  if (!host([&] { return g_fake.control(s, {}, {}); }).ok()) fail("control request refused", request);
}

// Host: the first `size` bytes of g_wire (one link frame) over bulk OUT in
// 64-byte packets, with a main-loop service() after each (a NAKed packet
// is sent again after it). The twin link gets the same bytes.
void send_frame(std::size_t size) noexcept {
  if (size == 0) fail("link frame not built");
  const std::span<const std::uint8_t> bytes(g_wire, size);
  std::size_t sent = 0;
  for (int tries = 0; sent < size; ++tries) {
    if (tries > 64) fail("bulk OUT keeps NAKing", static_cast<std::uint32_t>(sent));
    const std::size_t n = size - sent < 64 ? size - sent : 64;
    const Handshake h = host([&] { return g_fake.out_token(usb::composite::kCdcDataOut, bytes.subspan(sent, n)); });
    if (h == Handshake::kStall) fail("bulk OUT stalled");
    if (h == Handshake::kAck) sent += n;
    service();
  }
  timed(g_jobs.link, [&] {
    std::uint32_t replied = 0;
    for (const std::uint8_t b : bytes) replied += static_cast<std::uint32_t>(g_twin.receive(b).size());
    g_sink = g_sink + replied;
  });
}

// Host: reads `ep` until it NAKs; each packet goes to `consume(packet)`.
template <class F>
void read_until_nak(usb::EndpointAddress ep, F&& consume) noexcept {
  std::uint8_t packet[64];
  for (int guard = 0; guard < 64; ++guard) {
    std::size_t n = 0;
    const Handshake h = host([&] { return g_fake.in_token(ep, packet, n); });
    if (h == Handshake::kNak) return;
    if (h == Handshake::kStall) fail("IN endpoint stalled", ep);
    consume(std::span<const std::uint8_t>(packet, n));
  }
  fail("IN endpoint never NAKs", ep);
}

// Host: the link replies waiting on bulk IN (each must be a success; an
// 0x86 ack's payload is kept), then a main-loop service().
void read_replies(std::uint32_t expected) noexcept {
  const std::uint32_t before = g_replies_ok;
  g_reply_bytes = 0;
  read_until_nak(usb::composite::kCdcDataIn, [](std::span<const std::uint8_t> packet) {
    g_reply_bytes += packet.size();
    for (const std::uint8_t b : packet) {
      if (g_replies.push(b) != link::StreamDecoder::Event::kFrame) continue;
      const link::Reply r = g_client.accept(g_replies.frame());
      if (!r.ok()) fail("link error reply", static_cast<std::uint32_t>(r.type));
      if (r.type == link::MessageType::kMuscleStateAck && !link::decode_muscle_state_ack(r.payload, g_last_ack)) {
        fail("bad muscle state ack");
      }
      ++g_replies_ok;
    }
  });
  service();
  if (g_replies_ok - before != expected) fail("link replies missing", g_replies_ok - before);
}

// One period of the loop as described at the top; `period_job` gets its
// runtime work.
void run_period(app::SyntheticFrames<Model>& frames, Job& period_job) noexcept {
  firmware::SensorFrame<Model> frame;
  frames.next(frame);
  app::MuscleState<Model> muscle;
  float unused_loadcells_N[Loop::kLoadcellSlots];
  app::split_frame<Model>(frame, muscle, unused_loadcells_N);
  g_frame_bytes = g_client.muscle_state(muscle, g_wire);
  send_frame(g_frame_bytes);
  read_replies(1);

  Loop& loop = g_link.loop();
  Loop::LoadcellReading reading;
  reading.valid = board::read_loadcells(reading.newtons);
  const std::uint32_t ticks_per_period = board::description().tick_hz / board::kPeriodHz;
  timed(period_job, [&] {
    const std::uint32_t t0 = board::ticks();
    loop.run_period(reading, board::overrun_periods());
    loop.end_period(board::ticks() - t0, ticks_per_period);
  });
  const app::PeriodRecord<Model>& record = loop.latest();
  if (record.sequence != g_last_ack) fail("the muscle state was not used by the next record", record.sequence);
  if ((record.flags & app::kRecordStepped) == 0 || (record.flags & app::kRecordStaleMuscleState) != 0) {
    fail("record not stepped on a fresh muscle state", record.flags);
  }

  timed(g_jobs.publish, [&] { g_usb.publish(record); });
  const std::uint64_t records = g_telemetry.stats().records;
  g_hid_bytes = 0;
  read_until_nak(usb::composite::kHidReportIn, [](std::span<const std::uint8_t> report) {
    g_hid_bytes += report.size();
    if (g_telemetry.push(report) == usb::TelemetryDecoder<Model>::Event::kBadReport) fail("bad HID report");
  });
  service();
  if (g_telemetry.stats().records != records + 1 || g_telemetry.record().sequence != record.sequence) {
    fail("HID record missing", record.sequence);
  }
}

void mode(firmware::Mode m) noexcept {
  send_frame(g_client.set_mode(m, g_wire));
  read_replies(1);
}

// Runs f() with every job as it was before (work that is not reported).
template <class F>
void untimed(F&& f) noexcept {
  const Jobs saved = g_jobs;
  f();
  g_jobs = saved;
}

}  // namespace

int main() {
  board::init();
  {
    app::Text<160> line;
    line << "bench board=" << board::description().name << " numeric=q15 tick_hz=" << board::description().tick_hz
         << " model=";
    line.hex(Model::kModelHash) << " periods=" << kPeriods << '\n';
    emit(line);
  }

  app::SyntheticFrames<Model> frames(0xB05B0001u);
  untimed([&] {
    // Enumeration, the link session's start, the detector's history.
    g_usb.start();
    host([] {
      g_fake.bus_reset();
      return 0;
    });
    const std::uint8_t standard_out = usb::request_type(false, usb::RequestKind::kStandard, usb::Recipient::kDevice);
    control(standard_out, usb::request::kSetAddress, 5, 0);
    control(standard_out, usb::request::kSetConfiguration, 1, 0);
    if (g_usb.device().state() != usb::DeviceState::kConfigured) fail("not configured");
    control(usb::request_type(false, usb::RequestKind::kClass, usb::Recipient::kInterface),
            usb::cdc::kSetControlLineState, 3, usb::composite::kCdcCommInterface);  // DTR + RTS, as a terminal does
    send_frame(g_client.reset(g_wire));
    read_replies(1);
    mode(firmware::Mode::kDetect);
    for (int k = 0; k < kWarmup; ++k) run_period(frames, g_jobs.period_detect);
  });
  for (int k = 0; k < kPeriods; ++k) run_period(frames, g_jobs.period_detect);
  untimed([&] {  // the mode change and the first control period (it takes the reference)
    mode(firmware::Mode::kControl);
    run_period(frames, g_jobs.period_control);
  });
  for (int k = 0; k < kPeriods; ++k) run_period(frames, g_jobs.period_control);

  constexpr int kUsbReps = 2 * kPeriods;
  report("period_detect", kPeriods, g_jobs.period_detect);
  report("period_control", kPeriods, g_jobs.period_control);
  report("usb_service", kUsbReps, g_jobs.service);
  report("usb_publish", kUsbReps, g_jobs.publish);
  report("usb_events", kUsbReps, g_jobs.events);
  report("link", kUsbReps, g_jobs.link);
  report("host", kUsbReps, g_jobs.host);

  Job idle;
  timed(idle, [] {
    for (int k = 0; k < kIdleCalls; ++k) g_usb.service();
  });
  report("service_idle", kIdleCalls, idle);
  Job overhead;
  for (int k = 0; k < kOverheadPairs; ++k) timed(overhead, [] {});
  report("ticks_overhead", kOverheadPairs, overhead);

  {
    const usb::TelemetryStats& t = g_telemetry.stats();
    app::Text<256> line;
    line << "check frame_bytes=" << g_frame_bytes << " reply_bytes=" << g_reply_bytes << " hid_bytes=" << g_hid_bytes
         << " replies_ok=" << g_replies_ok << " records=" << t.records << " dropped=" << t.dropped
         << " hid_sets_sent=" << g_usb.hid().sets_sent() << " hid_overwritten=" << g_usb.hid().overwritten()
         << " cdc_dropped_reply_bytes=" << g_usb.cdc().dropped_reply_bytes()
         << " babble=" << g_fake.babble_errors() << '\n';
    emit(line);
    if (t.dropped != 0 || g_usb.hid().overwritten() != 0 || g_usb.cdc().dropped_reply_bytes() != 0 ||
        g_fake.babble_errors() != 0) {
      fail("losses on the USB path");
    }
  }
  {
    app::Text<240> line;
    line << "memory stack_used=" << board::stack_used_bytes() << " stack=" << board::stack_size_bytes()
         << " usb_device=" << sizeof(Usb) << " usb_core=" << sizeof(usb::UsbDevice) << " cdc=" << sizeof(Usb::Cdc)
         << " hid=" << sizeof(Usb::Hid) << " dfu_mode=" << sizeof(usb::DfuMode)
         << " dfu_runtime=" << sizeof(usb::DfuRuntime) << " device_link=" << sizeof(DeviceLink)
         << " runtime=" << sizeof(Runtime) << '\n';
    emit(line);
  }
  app::Text<8> end;
  end << "end\n";
  emit(end);
  board::exit(0);
}
