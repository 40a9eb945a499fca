// The PB-state table and the training record of a model file
// (trainer/training_record.h).
#include "trainer/training_record.h"

#include <gtest/gtest.h>

#include <regex>
#include <stdexcept>

namespace hadynet::trainer {
namespace {

LogSequence seq(const std::string& file, const std::string& state, const std::string& object) {
  LogSequence s;
  s.file = file;
  s.state = state;
  s.object = object;
  return s;
}

// Rows sorted by state name whatever the log order; each log points at its state's row.
TEST(PbStateTable, OneRowPerStateSortedByName) {
  const PbStateTable t = pb_state_table({seq("a.csv", "Sphere/i1/w0", "Sphere"), seq("b.csv", "Box/i1/w0", "Box"),
                                         seq("c.csv", "Sphere/i1/w0", "Sphere")});
  ASSERT_EQ(t.states.size(), 2u);
  EXPECT_EQ(t.states[0].name, "Box/i1/w0");
  EXPECT_EQ(t.states[0].object, "Box");
  EXPECT_EQ(t.states[1].name, "Sphere/i1/w0");
  EXPECT_EQ(t.state_of_sequence, (std::vector<int>{1, 0, 1}));
}

TEST(PbStateTable, OneStateWithTwoObjectsNamesTheLog) {
  try {
    pb_state_table({seq("a.csv", "s", "Box"), seq("b.csv", "s", "Sphere")});
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("b.csv"), std::string::npos) << what;
    EXPECT_NE(what.find("'Sphere'"), std::string::npos) << what;
    EXPECT_NE(what.find("'Box'"), std::string::npos) << what;
  }
}

TEST(TrainingRecord, HyperParametersKeepTheGivenTexts) {
  TrainOptions o;
  o.epochs = 7;
  o.variable_pb = false;
  const auto h = training_hyper_parameters(o, {30, "0.001", "0.2", 900, 100});
  EXPECT_EQ(h.at("epochs"), "7");
  EXPECT_EQ(h.at("steps"), "30");
  EXPECT_EQ(h.at("lr"), "0.001");
  EXPECT_EQ(h.at("held_out_fraction"), "0.2");
  EXPECT_EQ(h.at("variable_pb"), "false");
  EXPECT_EQ(h.at("train_windows"), "900");
  EXPECT_EQ(h.at("held_out_windows"), "100");
}

TEST(TrainingRecord, UtcTimeIsIso8601) {
  EXPECT_TRUE(std::regex_match(utc_now(), std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)"))) << utc_now();
}

}  // namespace
}  // namespace hadynet::trainer
