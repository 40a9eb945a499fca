// datalog/robot_profile.h: the profile survives log metadata, malformed
// values name the file and the key, and an empty profile writes nothing.
#include "datalog/robot_profile.h"

#include <gtest/gtest.h>

#include "datalog/log_error.h"

namespace hadynet::datalog {
namespace {

RobotProfile full_profile() {
  RobotProfile p;
  p.delta_groups = {"l", "th"};
  p.force_groups = {"f", "fc"};
  p.angle_groups = {"th"};
  p.length_groups = {"l"};
  p.control_commands = {"u3", "u4"};
  p.board_group = "fc";
  p.contact_sums = {{"tips", {"fc0", "fc1"}}, {"palm", {"fc2"}}};
  return p;
}

TEST(RobotProfile, MetadataRoundTrip) {
  LogMetadata m;
  write_profile(full_profile(), m);
  EXPECT_EQ(m.get("delta_groups"), "l,th");
  EXPECT_EQ(m.get("contact_sums"), "tips=fc0+fc1 palm=fc2");
  EXPECT_EQ(read_profile(m, "a.csv"), full_profile());
}

TEST(RobotProfile, EmptyProfileWritesNothingAndReadsBackEmpty) {
  LogMetadata m;
  write_profile(RobotProfile{}, m);
  EXPECT_TRUE(m.entries().empty());
  EXPECT_TRUE(read_profile(m, "a.csv").empty());
}

TEST(RobotProfile, NoneIsAnEmptyList) {
  EXPECT_TRUE(split_list("none").empty());
  EXPECT_TRUE(split_list("").empty());
  EXPECT_EQ(split_list("a,b"), (std::vector<std::string>{"a", "b"}));
}

TEST(RobotProfile, MalformedValuesNameFileAndKey) {
  const auto message_of = [](const char* key, const char* value) {
    LogMetadata m;
    m.set(key, value);
    try {
      read_profile(m, "logs/a.csv");
    } catch (const LogError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  for (const auto& [key, value] : std::vector<std::pair<const char*, const char*>>{
           {"force_groups", "f,,fc"},
           {"contact_sums", "tips"},
           {"contact_sums", "tips=fc0 tips=fc1"},
           {"contact_sums", "Tips=fc0"},
           {"contact_sums", "tips=fc0++fc1"},
           {"board_group", "f c"}}) {
    const std::string m = message_of(key, value);
    EXPECT_NE(m.find("logs/a.csv"), std::string::npos) << key << "=" << value << ": " << m;
    EXPECT_NE(m.find(key), std::string::npos) << key << "=" << value << ": " << m;
  }
}

}  // namespace
}  // namespace hadynet::datalog
