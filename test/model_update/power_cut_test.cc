// Power cuts at every flash operation of an update, of a revert and of an
// interrupted trial, and random multi-cut sequences (power_cut_harness.h).
// Every test prints "power cuts <name>: C cuts, N cut points, M unbootable
// states", records them as test properties, and the run ends with the
// totals.
#include <gtest/gtest.h>

#include <cstdio>

#include "test/model_update/power_cut_harness.h"

namespace hadynet::model_update::test {
namespace {

struct Totals {
  int cuts = 0;
  int cut_points = 0;
  int unbootable = 0;
};
Totals g_totals;

class PrintTotals final : public testing::Environment {
 public:
  void TearDown() override {
    std::printf("power cuts total: %d cuts, %d cut points, %d unbootable states\n", g_totals.cuts,
                g_totals.cut_points, g_totals.unbootable);
  }
};
[[maybe_unused]] testing::Environment* const g_print_totals = testing::AddGlobalTestEnvironment(new PrintTotals);

void expect_all_bootable(const std::string& name, const CutReport& r, int at_least) {
  report_cuts(name, r);
  g_totals.cuts += r.cuts;
  g_totals.cut_points += r.cut_points;
  g_totals.unbootable += r.unbootable;
  EXPECT_GE(r.cut_points, at_least);
  EXPECT_EQ(r.unbootable, 0);
}

Bytes payload_bytes(const Bytes& image) { return Bytes(image.begin() + kImageHeaderSize, image.end()); }

const Bytes& old_image() {
  static const Bytes image = small_image(1, 10);
  return image;
}
const Bytes& failed_image() {
  static const Bytes image = small_image(2, 20);
  return image;
}
const Bytes& new_image() {
  static const Bytes image = small_image(3, 30);
  return image;
}

// A: the old image, confirmed (in use). B: an image that failed its self-test.
const Bytes& old_confirmed() {
  static const Bytes cells = [] {
    SlotTestDevice d(small_layout(), small_identity());
    install(d, old_image());
    install(d, failed_image(), /*self_test_passes=*/false);
    return d.cells();
  }();
  return cells;
}

// ... and the new image written into B, not booted yet.
const Bytes& new_image_written() {
  static const Bytes cells = [] {
    SlotTestDevice d(small_layout(), small_identity(), old_confirmed());
    d.reboot_and_boot(true);
    if (write_image(d.slots(), new_image()) != UpdateError::kOk) ADD_FAILURE() << "setup";
    return d.cells();
  }();
  return cells;
}

void stop_unless_powered(SlotTestDevice& d, const std::function<void()>& next) {
  if (d.nor().powered()) next();
}

// The update: boot (A, no writes), stream the new image into B, boot it
// (tried, self-test, confirmed).
CutScenario update_scenario(bool recovery_passes) {
  CutScenario s{small_layout(), small_identity(), old_confirmed(), nullptr, {}, recovery_passes};
  s.script = [](SlotTestDevice& d) {
    d.reboot_and_boot(true);
    stop_unless_powered(d, [&] {
      if (write_image(d.slots(), new_image()) == UpdateError::kOk) d.reboot_and_boot(true);
    });
  };
  s.allowed = {payload_bytes(old_image())};
  if (recovery_passes) s.allowed.push_back(payload_bytes(new_image()));
  return s;
}

TEST(PowerCut, UpdateAtEveryOperation) {
  // The new image or the old one; never factory, a mix or unverified bytes.
  expect_all_bootable("update", cut_at_every_operation(update_scenario(true)), 20);
}

TEST(PowerCut, UpdateAtEveryOperationWithAFailingNewImage) {
  // If the new image fails its self-test after the cut, the old one runs.
  expect_all_bootable("update_failing", cut_at_every_operation(update_scenario(false)), 20);
}

TEST(PowerCut, SelfTestFailureRevertAtEveryOperation) {
  CutScenario s{small_layout(), small_identity(), new_image_written(), nullptr, {payload_bytes(old_image())}, true};
  s.script = [](SlotTestDevice& d) { d.reboot_and_boot(false); };
  // Even with a passing self-test afterwards, an image whose trial was cut
  // is not tried again: the old image runs.
  expect_all_bootable("revert", cut_at_every_operation(s), 2);
}

TEST(PowerCut, InterruptedTrialAtEveryOperation) {
  static const Bytes during_trial = [] {
    SlotTestDevice d(small_layout(), small_identity(), new_image_written());
    Bytes snapshot;
    ScriptedSelfTest dies;
    dies.during_run = [&] { snapshot = d.cells(); };
    d.reboot_and_boot(dies);
    return snapshot;
  }();
  CutScenario s{small_layout(), small_identity(), during_trial, nullptr, {payload_bytes(old_image())}, true};
  s.script = [](SlotTestDevice& d) { d.reboot_and_boot(true); };
  ASSERT_EQ(script_operations(s), 1u) << "the recovery boot writes B's invalid flag";
  expect_all_bootable("interrupted_trial", cut_at_every_operation(s), 1);
}

TEST(PowerCut, RevertToTheFactoryModelAtEveryOperation) {
  static const Bytes only_new = [] {
    SlotTestDevice d(small_layout(), small_identity());
    ScriptedSelfTest pass;
    d.slots().boot(pass);
    if (write_image(d.slots(), new_image()) != UpdateError::kOk) ADD_FAILURE() << "setup";
    return d.cells();
  }();
  CutScenario s{small_layout(), small_identity(), only_new, nullptr, {std::nullopt}, true};
  s.script = [](SlotTestDevice& d) { d.reboot_and_boot(false); };
  expect_all_bootable("revert_to_factory", cut_at_every_operation(s), 2);
}

const Bytes& downgrade_image() {
  static const Bytes image = [] {
    ModelImageHeader h = header_for(small_identity(), 1);
    h.downgrade_allowed = true;
    return sign_image(h, random_bytes(6000, 111), device_key());
  }();
  return image;
}

TEST(PowerCut, ForcedDowngradeAtEveryOperation) {
  // The update (B with image 2 in use; the downgrade to sequence 1 written
  // into A, then B marked invalid): B's image or the downgrade.
  CutScenario update{small_layout(), small_identity(), two_confirmed_images(), nullptr, {}, true};
  update.script = [](SlotTestDevice& d) {
    d.reboot_and_boot(true);
    stop_unless_powered(d, [&] { write_image(d.slots(), downgrade_image()); });
  };
  update.allowed = {random_bytes(6000, 20), payload_bytes(downgrade_image())};
  expect_all_bootable("forced_downgrade_update", cut_at_every_operation(update), 20);

  // Its trial: the documented effect of a forced downgrade is that the old
  // image is invalid for good, so a cut trial falls back to the factory model.
  static const Bytes written = [] {
    SlotTestDevice d(small_layout(), small_identity(), two_confirmed_images());
    d.reboot_and_boot(true);
    if (write_image(d.slots(), downgrade_image()) != UpdateError::kOk) ADD_FAILURE() << "setup";
    return d.cells();
  }();
  CutScenario trial{small_layout(), small_identity(), written, nullptr,
                    {payload_bytes(downgrade_image()), std::nullopt}, true};
  trial.script = [](SlotTestDevice& d) { d.reboot_and_boot(true); };
  expect_all_bootable("forced_downgrade_trial", cut_at_every_operation(trial), 2);
}

TEST(PowerCut, RandomMultiCutSequences) {
  // Fixed seed: the same sequences every run.
  expect_all_bootable("random_multi_cut", random_multi_cuts(update_scenario(true), 300, 0x5107u), 300);
}

}  // namespace
}  // namespace hadynet::model_update::test
