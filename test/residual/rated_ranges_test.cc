// --rated-range: parsing, and the known clips it adds to a model (the
// build's model: y channels l0..l7, f0..f7, fc0..fc8, th0, th1).
#include "trainer/residual/rated_ranges.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

#include "trainer/model_file.h"

namespace hadynet::trainer::residual {
namespace {

const HadynetModel& build_model() {
  static const HadynetModel model = load_model(HADYNET_MODEL_PATH);
  return model;
}

TEST(RatedRange, ParsesBothBoundsOrOne) {
  const RatedRange a = parse_rated_range("fc=0..50");
  EXPECT_EQ(a.name, "fc");
  EXPECT_EQ(a.low, 0.0);
  EXPECT_EQ(a.high, 50.0);
  const RatedRange b = parse_rated_range("y0=..10.5");
  EXPECT_FALSE(b.low.has_value());
  EXPECT_EQ(b.high, 10.5);
  const RatedRange c = parse_rated_range("f=-1e-3..");
  EXPECT_EQ(c.low, -1e-3);
  EXPECT_FALSE(c.high.has_value());
}

TEST(RatedRange, RefusesMalformedTextNamingIt) {
  for (const char* bad : {"fc", "fc=0", "=0..1", "fc=..", "fc=5..1", "fc=1..1", "fc=a..1", "fc=0..1x", "fc=0..nan"}) {
    try {
      parse_rated_range(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(bad[0] == '=' ? "=0..1" : bad), std::string::npos) << e.what();
    }
  }
}

TEST(RatedRange, ClipsEveryChannelOfAGroupAndAChannelsOwnRangeWins) {
  std::vector<OutputClip> added;
  const HadynetModel m =
      with_rated_ranges(build_model(), {parse_rated_range("fc=0..50"), parse_rated_range("fc3=..20")}, &added);
  // fc0..fc8: lower 0 and upper 50, except fc3: only its own upper 20.
  EXPECT_EQ(added.size(), 8u * 2 + 1);
  const auto has = [&](const std::string& ch, int side, double rail) {
    return std::count(m.sensor.clips.begin(), m.sensor.clips.end(), OutputClip{ch, side, rail}) == 1;
  };
  EXPECT_TRUE(has("fc0", -1, 0.0));
  EXPECT_TRUE(has("fc8", +1, 50.0));
  EXPECT_TRUE(has("fc3", +1, 20.0));
  EXPECT_FALSE(has("fc3", -1, 0.0));
  EXPECT_NO_THROW(m.check_consistent());
  // Nothing else changes.
  EXPECT_TRUE(m.params.enc_weight == build_model().params.enc_weight);
}

TEST(RatedRange, KeepsAClipTheModelAlreadyHas) {
  HadynetModel fixed = build_model();
  fixed.sensor.clips.push_back({"fc6", +1, 2.04});  // e.g. a rail --fix found
  std::vector<OutputClip> added;
  const HadynetModel m = with_rated_ranges(fixed, {parse_rated_range("fc6=0..50")}, &added);
  ASSERT_EQ(added.size(), 1u);
  EXPECT_EQ(added[0], (OutputClip{"fc6", -1, 0.0}));
  EXPECT_EQ(std::count(m.sensor.clips.begin(), m.sensor.clips.end(), OutputClip{"fc6", +1, 2.04}), 1);
}

TEST(RatedRange, ANameThatIsNoOutputIsAnError) {
  EXPECT_THROW(with_rated_ranges(build_model(), {parse_rated_range("u=0..1")}, nullptr), std::invalid_argument);
  EXPECT_THROW(with_rated_ranges(build_model(), {parse_rated_range("fc9=0..1")}, nullptr), std::invalid_argument);
}

// A channel's range (rated_range_of): its own wins over its group's; none
// for a channel neither names.
TEST(RatedRange, AChannelsOwnRangeWinsOverItsGroups) {
  const std::vector<RatedRange> ranges = {parse_rated_range("fc=0..50"), parse_rated_range("fc3=0..20")};
  ASSERT_NE(rated_range_of(ranges, "fc1"), nullptr);
  EXPECT_EQ(rated_range_of(ranges, "fc1")->high, 50.0);
  ASSERT_NE(rated_range_of(ranges, "fc3"), nullptr);
  EXPECT_EQ(rated_range_of(ranges, "fc3")->high, 20.0);
  EXPECT_EQ(rated_range_of(ranges, "f1"), nullptr);
}

}  // namespace
}  // namespace hadynet::trainer::residual
