#include "factors/depth_factor.h"

#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include "auvdock/geometry/pose3.h"
#include "factors/pose_manifold.h"

namespace auvdock {
namespace {

const Eigen::Vector3d kDown(0.0, 0.0, 9.81);
const Eigen::Vector3d kLeverArm(0.3, -0.1, 0.2);

Pose3 TiltedPose() {
  return Pose3(Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 0.5).normalized())),
               Eigen::Vector3d(1.0, -2.0, -3.5));
}

// Known answer: the sensor's depth is the dock origin's plus the sensor's z in D (down).
TEST(DepthFactorTest, ResidualIsTheWhitenedDepthError) {
  const Pose3 T_D_B = TiltedPose();
  const double sensor_z = (T_D_B * kLeverArm).z();
  const double true_depth = 30.0 + sensor_z;
  const DepthFactor exact(true_depth, 0.02, 30.0, kDown, kLeverArm);
  const DepthFactor off(true_depth + 0.05, 0.02, 30.0, kDown, kLeverArm);
  double pose[kPoseSize];
  PoseToBlock(T_D_B, pose);
  double r = 1.0;
  ASSERT_TRUE(exact(pose, &r));
  EXPECT_NEAR(r, 0.0, 1e-12);
  ASSERT_TRUE(off(pose, &r));
  EXPECT_NEAR(r, -2.5, 1e-9);  // 5 cm shallower than measured: -0.05 / 0.02
}

TEST(DepthFactorTest, JacobiansPassTheGradientCheckerWithThePoseManifold) {
  std::unique_ptr<ceres::CostFunction> cost(
      DepthFactor::Create(31.7, 0.02, 30.0, kDown, kLeverArm));
  const PoseManifold manifold;
  std::vector<const ceres::Manifold*> manifolds = {&manifold};
  const ceres::GradientChecker checker(cost.get(), &manifolds, ceres::NumericDiffOptions());
  double pose[kPoseSize];
  PoseToBlock(TiltedPose(), pose);
  const double* parameters[1] = {pose};
  ceres::GradientChecker::ProbeResults results;
  checker.Probe(parameters, 1e-7, &results);
  // Absolute comparison: a turn about the vertical leaves the depth alone, and the checker's
  // relative error of two zeros (1e-16 against 1e-13) is meaningless.
  ASSERT_EQ(results.local_jacobians.size(), 1u);
  EXPECT_LT((results.local_jacobians[0] - results.local_numeric_jacobians[0]).cwiseAbs().maxCoeff(),
            1e-8)
      << results.error_log;
  // Straight down along z: d r / d p_z = 1 / sigma.
  EXPECT_NEAR(results.local_jacobians[0](0, 2), 50.0, 1e-9);
}

TEST(DepthFactorTest, RejectsBadInput) {
  const auto make = [](double d, double sigma, const Eigen::Vector3d& down) {
    return DepthFactor(d, sigma, 30.0, down, kLeverArm);
  };
  EXPECT_THROW(make(std::nan(""), 0.02, kDown), std::invalid_argument);
  EXPECT_THROW(make(31.0, 0.0, kDown), std::invalid_argument);
  EXPECT_THROW(make(31.0, 0.02, Eigen::Vector3d::Zero()), std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
