// CheckLightCandidate's decisions on given evidence (light_candidate_checks.h), known answers: the
// measurements themselves are exercised on drawn images in blob_light_detector_test.cc.
#include "auvdock/vision/light_candidate_checks.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace auvdock {
namespace {

// A saturated core of radius core_radius_px at the blob scale sigma_px, peak 200 over a floor of
// 85 (contrast 115), its ring's brightest sector peak_drop below the peak and its 5th dimmest
// 100 below; a halo of the lights' colour, not of its surroundings'.
struct Candidate {
  BlobCandidate blob;
  LightCore core;
  LightCandidateEvidence evidence;
};

Candidate SaturatedCore(double sigma_px, double core_radius_px, double peak_drop) {
  Candidate c;
  c.blob.x = 100;
  c.blob.y = 100;
  c.blob.sigma_px = sigma_px;
  c.blob.response = 60.0;
  c.core.uv = Eigen::Vector2d(100.0, 100.0);
  c.core.peak = 200.0;
  c.core.floor = 85.0;
  c.core.radius_px = core_radius_px;
  c.core.area_px = static_cast<int>(3.14159 * core_radius_px * core_radius_px + 0.5);
  c.evidence.halo_excess = 80.0;
  c.evidence.surroundings_excess = 5.0;
  c.evidence.peak_drop = peak_drop;
  c.evidence.open_drop = 100.0;
  c.evidence.flatness = 0.7;
  c.evidence.saturated = true;
  return c;
}

std::string Check(const Candidate& c, const LightCandidateCheckOptions& options = {}) {
  return CheckLightCandidate(c.blob, c.core, c.evidence, /*has_colour=*/true, options);
}

// A few pixels' core at the scale of the structure it sits on (a bump on the edge of a lit funnel
// or deck, 0.08 sigma), barely above its brightest sector, is not a light; a saturated light in a
// wide glow, as small against its scale but far above its whole ring, is; and a core as large as
// its scale may have a bright structure in one sector (a LED beside a white funnel).
TEST(CheckLightCandidate, ASmallCoreMustStandAboveEverySectorOfItsRing) {
  const std::string bump = Check(SaturatedCore(13.4, 1.1, 10.0));
  EXPECT_EQ(bump.rfind("not a peak", 0), 0u) << bump;
  EXPECT_EQ(Check(SaturatedCore(13.4, 1.1, 90.0)), "");    // a LED in a wide glow
  EXPECT_EQ(Check(SaturatedCore(13.4, 8.0, 10.0)), "");    // a LED beside a funnel
  EXPECT_EQ(Check(SaturatedCore(13.4, 2.8, 10.0)), "");    // just above 0.2 sigma
  const std::string below = Check(SaturatedCore(13.4, 2.6, 34.0));  // just below it, drop 0.3
  EXPECT_EQ(below.rfind("not a peak", 0), 0u) << below;
  EXPECT_EQ(Check(SaturatedCore(13.4, 2.6, 35.0)), "");
  LightCandidateCheckOptions off;
  off.small_core_sigmas = 0.0;
  EXPECT_EQ(Check(SaturatedCore(13.4, 1.1, 10.0), off), "");
}

// Lowe's edge test with r = 10: a ratio of the principal curvatures above 10, i.e.
// tr^2 / det above 12.1, or a Hessian that is not negative definite, is a ridge.
TEST(CheckLightCandidate, ARidgeIsNotABlob) {
  Candidate c = SaturatedCore(4.0, 3.0, 90.0);
  c.evidence.curvature_ratio = 4.0;  // a round blob
  EXPECT_EQ(Check(c), "");
  c.evidence.curvature_ratio = 12.0;
  EXPECT_EQ(Check(c), "");
  c.evidence.curvature_ratio = 12.2;
  EXPECT_EQ(Check(c).rfind("a ridge", 0), 0u) << Check(c);
  c.evidence.curvature_ratio = std::numeric_limits<double>::infinity();
  EXPECT_EQ(Check(c).rfind("a ridge", 0), 0u) << Check(c);
  LightCandidateCheckOptions off;
  off.max_curvature_ratio = 0.0;
  EXPECT_EQ(Check(c, off), "");
}

// The measured ratio on drawn luma: a round Gaussian blob ~4 (equal curvatures), a 2:1 elliptic
// one (an interlaced or smeared light) well inside the limit, a bright line (a cable) and a line
// with a bump on it a ridge.
TEST(MeasureCandidateEvidence, CurvatureRatioTellsBlobsFromRidges) {
  auto image = [](double sx, double sy, bool line) {
    cv::Mat luma(241, 241, CV_32F, cv::Scalar(40.0f));
    for (int y = 0; y < luma.rows; ++y) {
      for (int x = 0; x < luma.cols; ++x) {
        const double dx = x - 120.0, dy = y - 120.0;
        const double v =
            line ? 100.0 * std::exp(-0.5 * dy * dy / 4.0) +
                       15.0 * std::exp(-0.5 * (dx * dx + dy * dy) / 4.0)
                 : 120.0 * std::exp(-0.5 * (dx * dx / (sx * sx) + dy * dy / (sy * sy)));
        luma.at<float>(y, x) += static_cast<float>(v);
      }
    }
    return luma;
  };
  auto ratio = [](const cv::Mat& luma, double sigma) {
    LightCore core;
    core.uv = Eigen::Vector2d(120.0, 120.0);
    core.peak = luma.at<float>(120, 120);
    core.floor = 40.0;
    core.radius_px = 2.0;
    return MeasureCandidateEvidence(luma, luma, core, sigma, 0.0, {}).curvature_ratio;
  };
  EXPECT_NEAR(ratio(image(3.0, 3.0, false), 3.0), 4.0, 0.2);
  EXPECT_LT(ratio(image(6.0, 3.0, false), 3.0), 7.0);
  EXPECT_NEAR(ratio(image(30.0, 30.0, false), 30.0), 4.0, 0.3);  // on the shrunk patch
  EXPECT_GT(ratio(image(1.0, 1.0, true), 2.0), 12.1);
  // Cut by the image's edge (the 3 sigma window leaves it): not measured.
  EXPECT_EQ(ratio(image(3.0, 3.0, false)(cv::Rect(0, 0, 125, 241)).clone(), 3.0), 0.0);
}

}  // namespace
}  // namespace auvdock
