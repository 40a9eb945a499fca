#include "test/model_update/power_cut_harness.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <algorithm>
#include <random>
#include <sstream>

namespace hadynet::model_update::test {

namespace {

constexpr std::uint32_t kSecondUpdateSequence = 100;
constexpr std::size_t kMaxFailuresKept = 5;

std::string describe(const BootChoice& c) {
  std::ostringstream o;
  o << model_source_text(c.source) << " seq " << c.sequence << " (" << c.payload.size() << " bytes)";
  return o.str();
}

void count(CutReport& r, const std::string& problem, const std::string& where) {
  ++r.cut_points;
  if (problem.empty()) return;
  ++r.unbootable;
  if (r.failures.size() < kMaxFailuresKept) r.failures.push_back(where + ": " + problem);
}

}  // namespace

Bytes image_for(const ModelIdentity& identity, std::uint32_t sequence, std::uint32_t seed) {
  return sign_image(header_for(identity, sequence), random_bytes(identity.payload_length, seed), device_key());
}

std::uint64_t script_operations(const CutScenario& s) {
  SlotTestDevice d(s.layout, s.identity, s.start);
  s.script(d);
  return d.nor().operation_count();
}

std::string check_recovery(SlotTestDevice& d, const CutScenario& s) {
  const BootChoice c = d.reboot_and_boot(s.recovery_self_test_passes);
  bool allowed = false;
  for (const std::optional<Bytes>& a : s.allowed) {
    if (!a.has_value()) {
      allowed = allowed || c.source == ModelSource::kFactory;
    } else if (c.source != ModelSource::kFactory) {
      allowed = allowed || std::equal(c.payload.begin(), c.payload.end(), a->begin(), a->end());
    }
  }
  if (!allowed) return "booted " + describe(c) + ", not an allowed model";
  const Bytes next = image_for(s.identity, kSecondUpdateSequence, 4242);
  const UpdateError e = write_image(d.slots(), next);
  if (e != UpdateError::kOk) return std::string("second update refused: ") + update_error_text(e);
  const BootChoice after = d.reboot_and_boot(true);
  const std::span<const std::uint8_t> want = payload_of(next);
  if (after.sequence != kSecondUpdateSequence || !std::equal(after.payload.begin(), after.payload.end(),
                                                              want.begin(), want.end())) {
    return "second update did not boot: " + describe(after);
  }
  return "";
}

CutReport cut_at_every_operation(const CutScenario& s) {
  CutReport r;
  const std::uint64_t total = script_operations(s);
  for (std::uint64_t n = 1; n <= total; ++n) {
    SlotTestDevice d(s.layout, s.identity, s.start);
    d.nor().cut_power_at(n);
    s.script(d);
    if (d.nor().powered()) {
      count(r, "the cut did not happen", "cut at " + std::to_string(n));
      continue;
    }
    ++r.cuts;
    d.nor().cut_power_at(0);
    d.nor().power_on();
    count(r, check_recovery(d, s), "cut at " + std::to_string(n));
  }
  return r;
}

CutReport random_multi_cuts(const CutScenario& s, int sequences, std::uint32_t seed) {
  CutReport r;
  std::mt19937 rng(seed);
  const std::uint64_t total = script_operations(s);
  for (int k = 0; k < sequences; ++k) {
    SlotTestDevice d(s.layout, s.identity, s.start);
    std::ostringstream where;
    where << "sequence " << k << ":";
    const int steps = 2 + static_cast<int>(rng() % 4);
    for (int step = 0; step < steps; ++step) {
      d.nor().power_on();
      const bool rerun_script = step == 0 || rng() % 3 == 0;  // the host retries the update
      if (rerun_script) {
        // Half the cuts among the script's last 3 operations (header, trial
        // flags), so the recovery boots have flags to write.
        const std::uint64_t last = std::min<std::uint64_t>(3, total);
        const std::uint64_t at = rng() % 2 == 0 ? 1 + rng() % total : total - rng() % last;
        d.nor().cut_power_at(d.nor().operation_count() + at);
        s.script(d);
        where << " script cut at +" << at;
      } else {
        const std::uint64_t at = 1 + rng() % 2;
        const bool verdict = rng() % 2 == 0;
        d.nor().cut_power_at(d.nor().operation_count() + at);
        d.reboot_and_boot(verdict);
        where << " boot(" << (verdict ? "pass" : "fail") << ") cut at +" << at;
      }
      if (!d.nor().powered()) {
        ++r.cuts;
        if (!rerun_script) ++r.boot_cuts;
      } else {
        where << " (not reached)";
      }
      d.nor().cut_power_at(0);
    }
    d.nor().power_on();
    count(r, check_recovery(d, s), where.str());
  }
  return r;
}

void report_cuts(const std::string& name, const CutReport& r) {
  const std::string in_boots = r.boot_cuts > 0 ? " (" + std::to_string(r.boot_cuts) + " in recovery boots)" : "";
  std::printf("power cuts %s: %d cuts%s, %d cut points, %d unbootable states\n", name.c_str(), r.cuts,
              in_boots.c_str(), r.cut_points, r.unbootable);
  testing::Test::RecordProperty(name + "_cuts", r.cuts);
  testing::Test::RecordProperty(name + "_cut_points", r.cut_points);
  testing::Test::RecordProperty(name + "_unbootable", r.unbootable);
  for (const std::string& f : r.failures) ADD_FAILURE() << name << ": " << f;
}

}  // namespace hadynet::model_update::test
