#include "auvdock/estimator/vision_factors.h"

#include <memory>

#include <ceres/problem.h>
#include <gtest/gtest.h>

#include "auvdock/sim/scenario.h"
#include "auvdock/vision/stereo_triangulation.h"
#include "factors/pose_manifold.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

// A problem holding one pose block on the production manifold.
struct PoseProblem {
  explicit PoseProblem(double* pose) : problem(Options()) {
    problem.AddParameterBlock(pose, kPoseSize, &manifold);
  }
  static ceres::Problem::Options Options() {
    ceres::Problem::Options options;
    options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    return options;
  }
  PoseManifold manifold;
  ceres::Problem problem;
};

// The default rig's stereo pair with the body placed so that the dock's first light is 9 m in
// front of the left camera, measured 0.4 m nearer than it is (a large depth error at that range).
struct StereoLightAhead {
  StereoLightAhead() {
    rig.stereo_left = calibration.FindCameraByRole(CameraRole::kStereoLeft);
    rig.stereo_right = calibration.FindCameraByRole(CameraRole::kStereoRight);
    rig.dock = &scenario.dock;
    const Pose3 T_D_B = (rig.stereo_left->T_B_C * T_S_D).Inverse();
    PoseToBlock(T_D_B, pose);
  }
  // The triangulation covariance of p_S's projections at pixel sigma `sigma`.
  Eigen::Matrix3d CovarianceAt(const Eigen::Vector3d& p_S, double sigma) const {
    const auto project = [&](const CameraCalibration& c) {
      const Eigen::Vector3d p_B = rig.stereo_left->T_B_C * p_S;
      return *c.intrinsics.Project(c.T_B_C.Inverse() * p_B);
    };
    return TriangulateLinear(project(*rig.stereo_left), project(*rig.stereo_right),
                             *rig.stereo_left, *rig.stereo_right, sigma)
        .covariance;
  }
  // 2 x the cost of the frame's one stereo residual (its squared Mahalanobis distance).
  double SquaredDistance(const VisionFrame& frame, const VisionFactorOptions& options) {
    PoseProblem problem(pose);
    int skipped = 0;
    const std::vector<VisionResidual> residuals =
        AddVisionFactors(&problem.problem, frame, rig, options, StateBlocks(pose), &skipped);
    EXPECT_EQ(residuals.size(), 1u);
    if (residuals.size() != 1u) return 0.0;
    double cost = 0.0;
    problem.problem.EvaluateResidualBlock(residuals[0].id, false, &cost, nullptr, nullptr);
    return 2.0 * cost;
  }
  const Scenario scenario = test::DefaultScenario();
  const Calibration calibration = MakeCalibration(scenario);
  VisionRig rig;
  const DockLight& light = scenario.dock.lights.front();
  const Pose3 T_S_D{Eigen::Quaterniond::Identity(),
                    Eigen::Vector3d(0.1, -0.2, 9.0) - scenario.dock.lights.front().p_D};
  const Eigen::Vector3d p_S_true = T_S_D * light.p_D;
  const Eigen::Vector3d p_S_measured = p_S_true * (8.6 / p_S_true.z());
  double pose[kPoseSize];
};

// With stereo_covariance_at_prediction the residual is whitened by the triangulation
// covariance at the light's predicted position (from the pose block); without it, by the
// measured point's, which is smaller (sigma_z ~ z^2) and so makes the same error look larger.
TEST(VisionFactorsTest, StereoCovarianceIsTakenAtThePredictedLight) {
  StereoLightAhead ahead;
  ASSERT_NE(ahead.rig.stereo_left, nullptr);
  ASSERT_NE(ahead.rig.stereo_right, nullptr);
  const double sigma = ahead.rig.stereo_left->pixel_noise_px;
  const Eigen::Matrix3d at_truth = ahead.CovarianceAt(ahead.p_S_true, sigma);
  const Eigen::Matrix3d at_measured = ahead.CovarianceAt(ahead.p_S_measured, sigma);
  ASSERT_LT(at_measured(2, 2), at_truth(2, 2));

  VisionFrame frame;
  frame.stereo.push_back({ahead.light.id, ahead.p_S_measured, at_measured});
  const Eigen::Vector3d e = ahead.p_S_measured - ahead.p_S_true;
  for (const bool at_prediction : {true, false}) {
    VisionFactorOptions options;
    options.use_mono = false;
    options.stereo_covariance_at_prediction = at_prediction;
    const Eigen::Matrix3d& expected_covariance = at_prediction ? at_truth : at_measured;
    const double d2 = ahead.SquaredDistance(frame, options);
    EXPECT_NEAR(d2, e.dot(expected_covariance.ldlt().solve(e)), 1e-6 * d2) << at_prediction;
  }
}

// A pair whose detections carry a centroid sigma 3 times the camera's (a saturated light) is
// whitened at that sigma, the predicted covariance scaled to it, and the correlated variance
// added to it: covariance x (s^2 + c) / s_computed^2.
TEST(VisionFactorsTest, StereoCovarianceIsTakenAtThePairsOwnPixelSigma) {
  StereoLightAhead ahead;
  ASSERT_NE(ahead.rig.stereo_left, nullptr);
  const double camera_sigma = ahead.rig.stereo_left->pixel_noise_px;
  const double own_sigma = 3.0 * camera_sigma;
  const double correlated = 0.04;
  VisionFrame frame;
  frame.stereo.push_back({ahead.light.id, ahead.p_S_measured,
                          ahead.CovarianceAt(ahead.p_S_measured, own_sigma), own_sigma});
  const Eigen::Vector3d e = ahead.p_S_measured - ahead.p_S_true;
  const double factor = (own_sigma * own_sigma + correlated);
  for (const bool at_prediction : {true, false}) {
    VisionFactorOptions options;
    options.use_mono = false;
    options.stereo_covariance_at_prediction = at_prediction;
    options.correlated_pixel_variance = correlated;
    const Eigen::Matrix3d expected =
        at_prediction ? ahead.CovarianceAt(ahead.p_S_true, camera_sigma) * factor /
                            (camera_sigma * camera_sigma)
                      : ahead.CovarianceAt(ahead.p_S_measured, own_sigma) * factor /
                            (own_sigma * own_sigma);
    const double d2 = ahead.SquaredDistance(frame, options);
    EXPECT_NEAR(d2, e.dot(expected.ldlt().solve(e)), 1e-6 * d2) << at_prediction;
  }
}

// A mono light behind the camera at the pose block's value cannot be evaluated there (the factor
// returns false and Ceres would fail the whole solve): it is skipped and counted, the others
// are added.
TEST(VisionFactorsTest, MonoLightBehindTheCameraAtTheEstimateIsSkipped) {
  const Scenario scenario = test::DefaultScenario();
  const Calibration calibration = MakeCalibration(scenario);
  VisionRig rig;
  rig.mono = calibration.FindCameraByRole(CameraRole::kMono);
  rig.dock = &scenario.dock;
  ASSERT_NE(rig.mono, nullptr);
  // The mono camera 2 m above the dock's first light, looking at it; a second light placed
  // 1 m above the camera (behind it) by editing a copy of the dock.
  DockModel dock = scenario.dock;
  const DockLight& light = dock.lights.front();
  const Pose3 T_C_D(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.0, 2.0) - light.p_D);
  const Pose3 T_D_B = (rig.mono->T_B_C * T_C_D).Inverse();
  DockLight behind = dock.lights.back();
  behind.p_D = T_D_B * (rig.mono->T_B_C * Eigen::Vector3d(0.1, 0.0, -1.0));
  dock.lights.back() = behind;
  rig.dock = &dock;
  double pose[kPoseSize];
  PoseToBlock(T_D_B, pose);

  VisionFrame frame;
  const Eigen::Vector2d uv = *rig.mono->intrinsics.Project(T_C_D * light.p_D);
  frame.mono.push_back({light.id, uv, 0.3});
  frame.mono.push_back({behind.id, uv + Eigen::Vector2d(5.0, 0.0), 0.3});
  PoseProblem problem(pose);
  VisionFactorOptions options;
  options.use_stereo = false;
  int skipped = 0;
  const std::vector<VisionResidual> residuals =
      AddVisionFactors(&problem.problem, frame, rig, options, StateBlocks(pose), &skipped);
  EXPECT_EQ(residuals.size(), 1u);
  EXPECT_EQ(skipped, 1);
  double cost = -1.0;
  EXPECT_TRUE(problem.problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr,
                               nullptr));
  EXPECT_NEAR(cost, 0.0, 1e-12);
}

}  // namespace
}  // namespace auvdock
