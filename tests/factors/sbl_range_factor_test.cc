#include "factors/sbl_range_factor.h"

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

const Eigen::Vector3d kTransducer(0.4, -0.15, 0.15);  // fore, port, on the hull's bottom
const Eigen::Vector3d kBeacon(0.2, -0.1, 0.3);

Pose3 TiltedPose() {
  return Pose3(Eigen::Quaterniond(Eigen::AngleAxisd(0.6, Eigen::Vector3d(0.3, -1, 2).normalized())),
               Eigen::Vector3d(-7.5, 1.2, -4.4));
}

// Known answer: the range through the lever arm, whitened.
TEST(SblRangeFactorTest, ResidualIsTheWhitenedRangeError) {
  const Pose3 T_D_B = TiltedPose();
  const double range = (T_D_B * kTransducer - kBeacon).norm();
  double pose[kPoseSize];
  PoseToBlock(T_D_B, pose);
  double r = 1.0;
  ASSERT_TRUE(SblRangeFactor(range, 0.05, kTransducer, kBeacon)(pose, &r));
  EXPECT_NEAR(r, 0.0, 1e-12);
  ASSERT_TRUE(SblRangeFactor(range + 0.1, 0.05, kTransducer, kBeacon)(pose, &r));
  EXPECT_NEAR(r, -2.0, 1e-9);
  // The lever arm turns with the body: at the body origin the range differs.
  ASSERT_TRUE(SblRangeFactor(range, 0.05, Eigen::Vector3d::Zero(), kBeacon)(pose, &r));
  EXPECT_NEAR(0.05 * r, (T_D_B.p - kBeacon).norm() - range, 1e-12);
  EXPECT_GT(std::abs(r), 1.0);
}

TEST(SblRangeFactorTest, JacobiansPassTheGradientCheckerWithThePoseManifold) {
  std::unique_ptr<ceres::CostFunction> cost(
      SblRangeFactor::Create(8.9, 0.03, kTransducer, kBeacon));
  const PoseManifold manifold;
  std::vector<const ceres::Manifold*> manifolds = {&manifold};
  const ceres::GradientChecker checker(cost.get(), &manifolds, ceres::NumericDiffOptions());
  double pose[kPoseSize];
  const Pose3 T_D_B = TiltedPose();
  PoseToBlock(T_D_B, pose);
  const double* parameters[1] = {pose};
  ceres::GradientChecker::ProbeResults results;
  checker.Probe(parameters, 1e-7, &results);
  ASSERT_EQ(results.local_jacobians.size(), 1u);
  EXPECT_LT((results.local_jacobians[0] - results.local_numeric_jacobians[0]).cwiseAbs().maxCoeff(),
            1e-6)
      << results.error_log;
  // The translation part is the unit line of sight from the beacon, over sigma.
  const Eigen::Vector3d los = (T_D_B * kTransducer - kBeacon).normalized();
  // The manifold's first three coordinates are the position (factors/pose_manifold.h).
  const auto& J = results.local_jacobians[0];
  EXPECT_NEAR(Eigen::Vector3d(J(0, 0), J(0, 1), J(0, 2)).dot(los), 1.0 / 0.03, 1e-6);
}

TEST(SblRangeFactorTest, ATransducerAtTheBeaconHasNoDirection) {
  const Pose3 T_D_B = TiltedPose();
  const Eigen::Vector3d beacon = T_D_B * kTransducer;
  double pose[kPoseSize];
  PoseToBlock(T_D_B, pose);
  std::unique_ptr<ceres::CostFunction> cost(SblRangeFactor::Create(0.5, 0.05, kTransducer, beacon));
  const double* parameters[1] = {pose};
  double r = 0.0;
  double jacobian[kPoseSize];
  double* jacobians[1] = {jacobian};
  ASSERT_TRUE(cost->Evaluate(parameters, &r, jacobians));
  EXPECT_NEAR(r, -10.0, 1e-9);
  for (double j : jacobian) EXPECT_TRUE(std::isfinite(j) && j == 0.0);
}

TEST(SblRangeFactorTest, RejectsBadInput) {
  EXPECT_THROW(SblRangeFactor(std::nan(""), 0.1, kTransducer, kBeacon), std::invalid_argument);
  EXPECT_THROW(SblRangeFactor(-1.0, 0.1, kTransducer, kBeacon), std::invalid_argument);
  EXPECT_THROW(SblRangeFactor(1.0, 0.0, kTransducer, kBeacon), std::invalid_argument);
  EXPECT_THROW(SblRangeFactor(1.0, 0.1, Eigen::Vector3d(INFINITY, 0, 0), kBeacon),
               std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
