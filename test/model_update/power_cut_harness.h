// Power cuts at every flash operation, as MCUboot's simulator does: a
// scenario (a starting flash and a script of what one power-on does: boot,
// update, boot the new image, ...) is replayed once per cut point N: power
// is cut at flash operation N (SimulatedNorFlash::cut_power_at: that
// operation half done, everything after refused), power comes back, the
// device boots again, and
//   * the boot must choose one of the scenario's allowed models (an image
//     whose payload equals an allowed payload byte for byte, or the
//     factory model where allowed): never a mix, never unverified;
//   * a second update (a new image, sequence 100) must then be accepted
//     and boot.
// A state failing either check counts as unbootable.
#ifndef HADYNET_TEST_MODEL_UPDATE_POWER_CUT_HARNESS_H_
#define HADYNET_TEST_MODEL_UPDATE_POWER_CUT_HARNESS_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "test/model_update/slot_test_device.h"

namespace hadynet::model_update::test {

struct CutScenario {
  SlotLayout layout;
  ModelIdentity identity;
  Bytes start;                                    // the flash before the script
  std::function<void(SlotTestDevice&)> script;    // one power-on's work; stops when the power is gone
  std::vector<std::optional<Bytes>> allowed;      // payloads a recovery boot may run; nullopt = the factory model
  bool recovery_self_test_passes = true;          // the verdict of the recovery boot's self-test
};

struct CutReport {
  int cuts = 0;        // power cuts that happened (several per state in multi-cut sequences)
  int boot_cuts = 0;   // of those, cuts in a recovery boot's flag writes (multi-cut sequences)
  int cut_points = 0;  // states reached by power cuts and checked
  int unbootable = 0;  // of those, states failing the checks
  std::vector<std::string> failures;  // the first few, for the test's message
};

// Flash operations the script performs without a cut.
std::uint64_t script_operations(const CutScenario& s);

// Cut at every operation 1..script_operations(s).
CutReport cut_at_every_operation(const CutScenario& s);

// `sequences` random multi-cut sequences (fixed seed), each 2..5 steps of
// power-on + work cut at a random operation (half of the script's cuts
// among its last 3 operations): first the script, then either the script
// again (the host retries the update; 1 in 3) or a recovery boot
// with a random self-test verdict cut at one of its first 2 operations
// (the flag writes; a step doing fewer operations is not cut). Then a clean
// recovery boot, checked as above (its verdict: the scenario's).
CutReport random_multi_cuts(const CutScenario& s, int sequences, std::uint32_t seed);

// The script's allowed outcomes after a clean recovery boot of `device`
// (powered on); "" if fine, else what is wrong. Then the second update.
std::string check_recovery(SlotTestDevice& device, const CutScenario& s);

// An image for `identity` with `sequence` and a payload from `seed`.
Bytes image_for(const ModelIdentity& identity, std::uint32_t sequence, std::uint32_t seed);

// Prints and records a report ("power cuts <name>: C cuts, N cut points, M
// unbootable states"); a failure per unbootable state kept.
void report_cuts(const std::string& name, const CutReport& r);

}  // namespace hadynet::model_update::test

#endif  // HADYNET_TEST_MODEL_UPDATE_POWER_CUT_HARNESS_H_
