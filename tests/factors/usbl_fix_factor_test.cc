#include "factors/usbl_fix_factor.h"

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

const Eigen::Vector3d kLeverArm(0.1, -0.05, -0.2);

Pose3 TiltedPose() {
  return Pose3(Eigen::Quaterniond(Eigen::AngleAxisd(0.6, Eigen::Vector3d(0.3, -1, 2).normalized())),
               Eigen::Vector3d(-7.5, 1.2, -4.4));
}

// Known answer: the transponder's position through the lever arm, whitened per axis.
TEST(UsblFixFactorTest, ResidualIsTheWhitenedTransponderError) {
  const Pose3 T_D_B = TiltedPose();
  const Eigen::Vector3d p_D_S = T_D_B * kLeverArm;
  double pose[kPoseSize];
  PoseToBlock(T_D_B, pose);
  Eigen::Vector3d r;
  ASSERT_TRUE(UsblFixFactor(p_D_S, 0.1, kLeverArm)(pose, r.data()));
  EXPECT_LT(r.norm(), 1e-12);
  ASSERT_TRUE(UsblFixFactor(p_D_S + Eigen::Vector3d(0.2, 0.0, -0.05), 0.1, kLeverArm)(pose, r.data()));
  EXPECT_NEAR(r.x(), -2.0, 1e-9);
  EXPECT_NEAR(r.y(), 0.0, 1e-9);
  EXPECT_NEAR(r.z(), 0.5, 1e-9);
  // Without the lever arm the body origin is compared: the arm's turn by R_D_B is in the model.
  ASSERT_TRUE(UsblFixFactor(p_D_S, 0.1, Eigen::Vector3d::Zero())(pose, r.data()));
  EXPECT_NEAR((0.1 * r - (T_D_B.p - p_D_S)).norm(), 0.0, 1e-12);
}

TEST(UsblFixFactorTest, JacobiansPassTheGradientCheckerWithThePoseManifold) {
  std::unique_ptr<ceres::CostFunction> cost(
      UsblFixFactor::Create(Eigen::Vector3d(-7.4, 1.0, -4.6), 0.09, kLeverArm));
  const PoseManifold manifold;
  std::vector<const ceres::Manifold*> manifolds = {&manifold};
  const ceres::GradientChecker checker(cost.get(), &manifolds, ceres::NumericDiffOptions());
  double pose[kPoseSize];
  PoseToBlock(TiltedPose(), pose);
  const double* parameters[1] = {pose};
  ceres::GradientChecker::ProbeResults results;
  checker.Probe(parameters, 1e-7, &results);
  // Absolute comparison: entries that are zero analytically come out ~1e-15 numerically, and
  // the checker's relative error of two such zeros is meaningless.
  ASSERT_EQ(results.local_jacobians.size(), 1u);
  EXPECT_LT((results.local_jacobians[0] - results.local_numeric_jacobians[0]).cwiseAbs().maxCoeff(),
            1e-6)
      << results.error_log;
  // Along x: d r_x / d p_x = 1 / sigma.
  EXPECT_NEAR(results.local_jacobians[0](0, 0), 1.0 / 0.09, 1e-9);
}

TEST(UsblFixFactorTest, RejectsBadInput) {
  EXPECT_THROW(UsblFixFactor(Eigen::Vector3d(std::nan(""), 0, 0), 0.1, kLeverArm),
               std::invalid_argument);
  EXPECT_THROW(UsblFixFactor(Eigen::Vector3d::Zero(), 0.0, kLeverArm), std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
