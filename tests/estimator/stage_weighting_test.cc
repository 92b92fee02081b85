#include "auvdock/estimator/stage_weighting.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include <gtest/gtest.h>

namespace auvdock {
namespace {

StageWeighting Paper(double min_share = 0.0) {
  StageWeightingOptions options;
  options.mode = StageWeightingMode::kPaperLightCount;
  options.min_share = min_share;
  return StageWeighting(options);
}

TEST(StageWeightingTest, DefaultIsPureInformationWeighting) {
  const StageWeighting weighting;
  EXPECT_EQ(weighting.options().mode, StageWeightingMode::kInformation);
  for (int n_s = 0; n_s < 8; ++n_s) {
    for (int n_m = 0; n_m < 8; ++n_m) {
      const StageWeights w = weighting.Compute(n_s, n_m);
      EXPECT_EQ(w.stereo, 1.0);
      EXPECT_EQ(w.mono, 1.0);
    }
  }
}

TEST(StageWeightingTest, PaperModeHandWorkedValues) {
  const StageWeighting weighting = Paper();
  // (6, 2): shares 0.75 / 0.25, c = 8 / (6 * 0.75 + 2 * 0.25) = 1.6.
  StageWeights w = weighting.Compute(6, 2);
  EXPECT_NEAR(w.stereo, 1.2, 1e-15);
  EXPECT_NEAR(w.mono, 0.4, 1e-15);
  // Equal counts: both 1.
  w = weighting.Compute(4, 4);
  EXPECT_NEAR(w.stereo, 1.0, 1e-15);
  EXPECT_NEAR(w.mono, 1.0, 1e-15);
  // One system alone (stereo only / mono only) or none: 1.
  for (const auto& [n_s, n_m] : {std::pair{5, 0}, std::pair{0, 3}, std::pair{0, 0}}) {
    w = weighting.Compute(n_s, n_m);
    EXPECT_EQ(w.stereo, 1.0);
    EXPECT_EQ(w.mono, 1.0);
  }
}

// The renormalisation keeps the mean weight per light at 1 and the ratio at the paper's.
TEST(StageWeightingTest, PaperModeKeepsTheTotalAndSplitsByCount) {
  for (const double floor : {0.0, 0.2, 0.5}) {
    const StageWeighting weighting = Paper(floor);
    for (int n_s = 1; n_s <= 12; ++n_s) {
      for (int n_m = 1; n_m <= 12; ++n_m) {
        const StageWeights w = weighting.Compute(n_s, n_m);
        EXPECT_GT(w.stereo, 0.0);
        EXPECT_GT(w.mono, 0.0);
        EXPECT_NEAR(n_s * w.stereo + n_m * w.mono, n_s + n_m, 1e-12) << n_s << "," << n_m;
        const double n = n_s + n_m;
        const double share_s = std::clamp(n_s / n, floor, 1.0 - floor);
        const double share_m = 1.0 - share_s;
        EXPECT_NEAR(w.stereo / w.mono, share_s / share_m, 1e-12) << n_s << "," << n_m;
      }
    }
  }
}

TEST(StageWeightingTest, FloorKeepsALoneLightFromBeingSilenced) {
  // (9, 1): split 0.9 / 0.1; with a 0.25 floor, 0.75 / 0.25, c = 10 / (9 * 0.75 + 1 * 0.25).
  const StageWeights plain = Paper().Compute(9, 1);
  const StageWeights floored = Paper(0.25).Compute(9, 1);
  EXPECT_NEAR(plain.mono / plain.stereo, 1.0 / 9.0, 1e-12);
  EXPECT_NEAR(floored.stereo, 0.75 * 10.0 / 7.0, 1e-12);
  EXPECT_NEAR(floored.mono, 0.25 * 10.0 / 7.0, 1e-12);
  // The floor leaves a split that is already inside it alone.
  const StageWeights inside = Paper(0.25).Compute(6, 2);
  EXPECT_NEAR(inside.stereo, 1.2, 1e-12);
  EXPECT_NEAR(inside.mono, 0.4, 1e-12);
  // A floor of 0.5 equalises the systems: both weights 1.
  const StageWeights equal = Paper(0.5).Compute(9, 1);
  EXPECT_NEAR(equal.stereo, 1.0, 1e-12);
  EXPECT_NEAR(equal.mono, 1.0, 1e-12);
}

TEST(StageWeightingTest, RejectsInvalidOptionsAndCounts) {
  StageWeightingOptions options;
  options.mode = StageWeightingMode::kPaperLightCount;
  for (const double bad : {-0.1, 0.51, std::numeric_limits<double>::quiet_NaN()}) {
    options.min_share = bad;
    EXPECT_THROW(StageWeighting{options}, std::invalid_argument) << bad;
  }
  options.min_share = 0.0;
  options.mode = static_cast<StageWeightingMode>(42);
  EXPECT_THROW(StageWeighting{options}, std::invalid_argument);
  const StageWeighting weighting;
  EXPECT_THROW(weighting.Compute(-1, 2), std::invalid_argument);
  EXPECT_THROW(Paper().Compute(3, -2), std::invalid_argument);
}

TEST(StageWeightingTest, ModeNamesRoundTrip) {
  for (const StageWeightingMode mode :
       {StageWeightingMode::kInformation, StageWeightingMode::kPaperLightCount}) {
    StageWeightingMode parsed = StageWeightingMode::kInformation;
    ASSERT_TRUE(ParseStageWeightingMode(StageWeightingModeName(mode), &parsed));
    EXPECT_EQ(parsed, mode);
  }
  StageWeightingMode untouched = StageWeightingMode::kPaperLightCount;
  EXPECT_FALSE(ParseStageWeightingMode("light_count", &untouched));
  EXPECT_EQ(untouched, StageWeightingMode::kPaperLightCount);
}

}  // namespace
}  // namespace auvdock
