// The words the residual analysis prints beside its numbers
// (trainer/residual/analysis.h): which PB each log used, and what a ranked
// hypothesis' figures mean. Issue 12: stdout said "PB auto" when a PB had
// been adapted, and listed negative explained shares beside p = 1e-201
// with nothing to tell them from an effect.
#include <gtest/gtest.h>

#include "trainer/residual/analysis.h"

namespace hadynet::trainer::residual {
namespace {

// Logs whose PB came from `sources` as compute_residuals labels them.
ResidualData logs_with(const std::vector<std::string>& sources) {
  ResidualData d;
  for (const auto& s : sources) {
    ResidualLog log;
    log.pb_source = s;
    log.pb_origin = s.rfind("state ", 0) == 0     ? ResidualLog::PbOrigin::kTrained
                    : s.rfind("adapted", 0) == 0 ? ResidualLog::PbOrigin::kAdapted
                                                 : ResidualLog::PbOrigin::kGiven;
    d.logs.push_back(log);
  }
  return d;
}

TEST(PbSummary, SaysWhenAPbWasAdapted) {
  const std::string s = pb_summary(
      logs_with({"state Cylinder/i1/w0", "state Box/i1/w0", "state Box/i1/w0", "adapted to the state's logs"}), "auto");
  EXPECT_EQ(s, "--pb auto: 3 logs with their state's trained PB, 1 log with a PB adapted to their state's logs "
               "(states the model was not trained on)");
}

TEST(PbSummary, ExplicitChoices) {
  EXPECT_EQ(pb_summary(logs_with({"adapted to the state's logs"}), "adapt"),
            "--pb adapt: 1 log with a PB adapted to their state's logs");
  EXPECT_EQ(pb_summary(logs_with({"zero", "zero"}), "zero"), "--pb zero: 2 logs with PB zero");
}

TEST(HypothesisStatus, NegativeExplainedIsNeverMistakenForAnEffect) {
  AttributionOptions o;  // alpha 0.01
  HypothesisResult r;
  r.p_adjusted = 1e-201;
  r.explained = -0.4;
  EXPECT_STREQ(hypothesis_status(r, o), "over-predicts held out");
  r.explained = 0.02;  // significant p, below the 0.1 floor
  EXPECT_STREQ(hypothesis_status(r, o), "below the floors");
  r.p_adjusted = 0.5;
  EXPECT_STREQ(hypothesis_status(r, o), "not significant");
  r.testable = false;
  EXPECT_STREQ(hypothesis_status(r, o), "not testable");
  r.testable = true;
  r.significant = true;
  EXPECT_STREQ(hypothesis_status(r, o), "significant");
}

}  // namespace
}  // namespace hadynet::trainer::residual
