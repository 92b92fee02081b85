#include "apps/run_summary.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace auvdock::cli {
namespace {

using ::testing::HasSubstr;

// The sensors' disagreement warnings: none below 20 samples or at most half (DVL) / a quarter
// (depth, without its offset estimated) refused; else one line naming the counts and what to
// check.
TEST(RunSummary, SensorDisagreementWarnings) {
  EstimatorStats stats;
  stats.dvl_used = 9;
  stats.dvl_rate_rejected = 10;  // 19 samples: too few to tell
  EXPECT_EQ(DvlDisagreementWarning(stats), "");
  stats.dvl_used = 10;
  stats.dvl_gated = 1;  // 11 of 21 refused
  EXPECT_THAT(DvlDisagreementWarning(stats), HasSubstr("refused 11 of 21 DVL samples"));
  EXPECT_THAT(DvlDisagreementWarning(stats), HasSubstr("T_B_S"));
  stats.dvl_used = 11;  // 11 of 22: half, not more
  EXPECT_EQ(DvlDisagreementWarning(stats), "");

  stats.depth_used = 15;
  stats.depth_gated = 6;  // more than a quarter of 21
  EXPECT_THAT(DepthDisagreementWarning(stats), HasSubstr("rejected 6 of 21 depth samples"));
  stats.depth_offset_m = 0.3;  // estimated: the gate's refusals are the sensor's business
  EXPECT_EQ(DepthDisagreementWarning(stats), "");

  stats.usbl_used = 4;
  stats.usbl_gated = 5;  // 9 fixes: too few
  EXPECT_EQ(UsblDisagreementWarning(stats), "");
  stats.usbl_gated = 6;
  EXPECT_THAT(UsblDisagreementWarning(stats), HasSubstr("refused 6 of 10 acoustic fixes"));
  EXPECT_THAT(UsblDisagreementWarning(stats), HasSubstr("dock frame D"));
}

}  // namespace
}  // namespace auvdock::cli
