// The batch smoother's model of time-correlated vision errors (estimator/batch_smoother.h):
// the added pixel variance N_c floor^2 against a Monte-Carlo AR(1) process, and its effect on
// the mono and stereo residuals (estimator/vision_factors.h).
#include <cmath>
#include <random>

#include <ceres/problem.h>
#include <gtest/gtest.h>

#include "auvdock/estimator/batch_smoother.h"
#include "auvdock/estimator/vision_factors.h"
#include "auvdock/sim/docking_simulator.h"
#include "factors/pose_manifold.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

TEST(CorrelatedVisionVarianceTest, ClosedFormAndOffSwitches) {
  // rho = exp(-0.1 / 2) = 0.951229: N_c = (1 + rho) / (1 - rho) = 40.0083.
  EXPECT_NEAR(CorrelatedVisionVariance(0.075, 2.0, 0.1), 40.0083 * 0.075 * 0.075, 1e-5);
  // tau >> dt: N_c -> 2 tau / dt.
  EXPECT_NEAR(CorrelatedVisionVariance(1.0, 100.0, 0.1) / 2000.0, 1.0, 1e-4);
  EXPECT_EQ(CorrelatedVisionVariance(0.0, 2.0, 0.1), 0.0);
  EXPECT_EQ(CorrelatedVisionVariance(0.1, 0.0, 0.1), 0.0);
  EXPECT_EQ(CorrelatedVisionVariance(0.1, 2.0, 0.0), 0.0);
  EXPECT_EQ(CorrelatedVisionVariance(0.1, std::nan(""), 0.1), 0.0);
}

// Over n frames the mean of a stationary AR(1) error has the variance s^2 N_c / n: the variance
// per frame that a least-squares fit over independent frames needs is N_c s^2.
TEST(CorrelatedVisionVarianceTest, MatchesTheVarianceOfTheMeanOfAnAr1Process) {
  const double s = 0.075, tau = 2.0, dt = 0.1;
  const double rho = std::exp(-dt / tau);
  const int n = 4000, runs = 400;
  std::mt19937_64 rng(42);
  std::normal_distribution<double> normal;
  double sum_sq = 0.0;
  for (int run = 0; run < runs; ++run) {
    double x = s * normal(rng), sum = 0.0;
    for (int k = 0; k < n; ++k) {
      if (k > 0) x = rho * x + s * std::sqrt(1.0 - rho * rho) * normal(rng);
      sum += x;
    }
    sum_sq += (sum / n) * (sum / n);
  }
  const double variance_of_mean = sum_sq / runs;
  EXPECT_NEAR(variance_of_mean * n / CorrelatedVisionVariance(s, tau, dt), 1.0, 0.2);
}

// The added variance de-weights a mono pixel (sigma^2 + v) and scales a stereo point's
// triangulation covariance by (sigma_px^2 + v) / sigma_px^2.
TEST(VisionFactorsTest, CorrelatedPixelVarianceDeweightsMonoAndStereoResiduals) {
  const Scenario scenario = test::DefaultScenario();
  const DockingSimulator simulator(scenario);
  const Calibration& calibration = simulator.calibration();
  VisionRig rig;
  rig.stereo_left = calibration.FindCameraByRole(CameraRole::kStereoLeft);
  rig.mono = calibration.FindCameraByRole(CameraRole::kMono);
  rig.dock = &scenario.dock;
  ASSERT_NE(rig.stereo_left, nullptr);
  ASSERT_NE(rig.mono, nullptr);
  const double sigma_px = rig.stereo_left->pixel_noise_px;
  ASSERT_GT(sigma_px, 0.0);

  const Pose3 T_D_B = simulator.trajectory().At(30.0).T_D_B;  // over the dock
  double pose[kPoseSize];
  Eigen::Map<Eigen::Vector3d> position(pose);
  Eigen::Map<Eigen::Quaterniond> rotation(pose + 3);
  position = T_D_B.p;
  rotation = T_D_B.q;
  const DockLight& light = scenario.dock.lights.front();
  const std::optional<Eigen::Vector2d> uv =
      rig.mono->intrinsics.Project((T_D_B * rig.mono->T_B_C).Inverse() * light.p_D);
  ASSERT_TRUE(uv.has_value());
  VisionFrame frame;
  frame.mono.push_back({light.id, *uv + Eigen::Vector2d(0.5, 0.0), sigma_px});
  const Eigen::Vector3d p_S = (T_D_B * rig.stereo_left->T_B_C).Inverse() * light.p_D;
  StereoLightObservation stereo;
  stereo.light_id = light.id;
  stereo.p_S = p_S + Eigen::Vector3d(0.002, -0.001, 0.01);
  stereo.covariance = Eigen::Vector3d(1e-6, 2e-6, 1e-4).asDiagonal();
  frame.stereo.push_back(stereo);

  // 2 cost (no loss) = the squared Mahalanobis distance of each residual.
  auto costs = [&](double correlated_pixel_variance) {
    ceres::Problem problem;
    VisionFactorOptions options;
    options.correlated_pixel_variance = correlated_pixel_variance;
    int skipped = 0;
    const std::vector<VisionResidual> residuals =
        AddVisionFactors(&problem, frame, rig, options, StateBlocks(pose), &skipped);
    EXPECT_EQ(skipped, 0);
    EXPECT_EQ(residuals.size(), 2u);
    std::array<double, 2> chi2{};  // mono, stereo
    for (const VisionResidual& r : residuals) {
      double cost = 0.0;
      problem.EvaluateResidualBlock(r.id, false, &cost, nullptr, nullptr);
      chi2[r.mono ? 0 : 1] = 2.0 * cost;
    }
    return chi2;
  };
  const std::array<double, 2> white = costs(0.0);
  EXPECT_NEAR(white[0], 0.25 / (sigma_px * sigma_px), 1e-6);
  const double added = 0.16;
  const std::array<double, 2> deweighted = costs(added);
  const double ratio = (sigma_px * sigma_px + added) / (sigma_px * sigma_px);
  EXPECT_NEAR(deweighted[0], 0.25 / (sigma_px * sigma_px + added), 1e-6);
  EXPECT_NEAR(deweighted[1], white[1] / ratio, 1e-9 * white[1]);
}

}  // namespace
}  // namespace auvdock
