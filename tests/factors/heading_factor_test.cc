#include "factors/heading_factor.h"

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

// A T-dock-like frame (z down) whose x axis points 30 degrees east of north.
HeadingReference DockFacing30Degrees() {
  DockModel dock;
  dock.gravity_D = Eigen::Vector3d(0.0, 0.0, 9.81);
  dock.heading_rad = M_PI / 6.0;
  return HeadingReference::OfDock(dock);
}

Pose3 Turned(double yaw, double pitch, double roll) {
  const Eigen::Quaterniond q = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  return Pose3(q, Eigen::Vector3d(-12.0, 3.0, -6.0));
}

// Known answers: a body turned 40 degrees about D's z (down) heads 30 + 40 = 70 degrees, whatever
// its pitch and roll; a sensor mounted 90 degrees to the right heads 90 degrees more; the
// residual wraps (a reading of 70 - 360 degrees is the same heading).
TEST(HeadingFactorTest, ResidualIsTheWrappedWhitenedHeadingError) {
  const HeadingReference reference = DockFacing30Degrees();
  const double deg = M_PI / 180.0;
  double pose[kPoseSize];
  PoseToBlock(Turned(40.0 * deg, 0.2, -0.15), pose);
  double r = 1.0;
  ASSERT_TRUE(HeadingFactor(70.0 * deg, 0.02, Eigen::Quaterniond::Identity(), reference)(pose, &r));
  EXPECT_NEAR(r, 0.0, 1e-9);
  ASSERT_TRUE(HeadingFactor(-290.0 * deg, 0.02, Eigen::Quaterniond::Identity(), reference)(pose, &r));
  EXPECT_NEAR(r, 0.0, 1e-9);
  ASSERT_TRUE(HeadingFactor(72.0 * deg, 0.02, Eigen::Quaterniond::Identity(), reference)(pose, &r));
  EXPECT_NEAR(r, -2.0 * deg / 0.02, 1e-9);
  const Eigen::Quaterniond starboard(Eigen::AngleAxisd(M_PI / 2.0, Eigen::Vector3d::UnitZ()));
  PoseToBlock(Turned(40.0 * deg, 0.0, 0.0), pose);
  ASSERT_TRUE(HeadingFactor(160.0 * deg, 0.02, starboard, reference)(pose, &r));
  EXPECT_NEAR(r, 0.0, 1e-9);
}

// A dock whose gravity is along +y (a vertical ring face): the reference axis is D's x, and a
// turn about y is a change of heading.
TEST(HeadingFactorTest, FollowsTheDocksOwnGravity) {
  DockModel dock;
  dock.gravity_D = Eigen::Vector3d(0.0, 9.81, 0.0);
  const HeadingReference reference = HeadingReference::OfDock(dock);
  // Body x along D's z after a turn of +90 degrees about y (down): heading of z from x about y.
  const Pose3 T_D_B(Eigen::Quaterniond(Eigen::AngleAxisd(-M_PI / 2.0, Eigen::Vector3d::UnitY())),
                    Eigen::Vector3d::Zero());
  const Eigen::Vector3d a_D = T_D_B.q * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(reference.HeadingOf(a_D), std::atan2(Eigen::Vector3d::UnitY().dot(
                                                       Eigen::Vector3d::UnitX().cross(a_D)),
                                                   a_D.x()),
              1e-12);
  double pose[kPoseSize];
  PoseToBlock(T_D_B, pose);
  double r = 1.0;
  ASSERT_TRUE(HeadingFactor(reference.HeadingOf(a_D), 0.05, Eigen::Quaterniond::Identity(),
                            reference)(pose, &r));
  EXPECT_NEAR(r, 0.0, 1e-12);
  EXPECT_NEAR(std::abs(reference.HeadingOf(a_D)), M_PI / 2.0, 1e-9);
}

TEST(HeadingFactorTest, JacobiansPassTheGradientCheckerWithThePoseManifold) {
  const Eigen::Quaterniond q_B_S(Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 0.1, 1.0).normalized()));
  std::unique_ptr<ceres::CostFunction> cost(
      HeadingFactor::Create(1.1, 0.03, q_B_S, DockFacing30Degrees()));
  const PoseManifold manifold;
  std::vector<const ceres::Manifold*> manifolds = {&manifold};
  const ceres::GradientChecker checker(cost.get(), &manifolds, ceres::NumericDiffOptions());
  double pose[kPoseSize];
  PoseToBlock(Turned(0.7, 0.25, -0.2), pose);
  const double* parameters[1] = {pose};
  ceres::GradientChecker::ProbeResults results;
  checker.Probe(parameters, 1e-7, &results);
  ASSERT_EQ(results.local_jacobians.size(), 1u);
  EXPECT_LT((results.local_jacobians[0] - results.local_numeric_jacobians[0]).cwiseAbs().maxCoeff(),
            1e-6)
      << results.error_log;
  // The position does not enter; a turn about the vertical (dtheta_D z) moves the heading one
  // for one: d r / d theta_z = 1 / sigma.
  EXPECT_LT(results.local_jacobians[0].leftCols<3>().cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(results.local_jacobians[0](0, 5), 1.0 / 0.03, 1e-6);
}

TEST(HeadingFactorTest, RejectsBadInput) {
  const HeadingReference reference = DockFacing30Degrees();
  EXPECT_THROW(HeadingFactor(std::nan(""), 0.02, Eigen::Quaterniond::Identity(), reference),
               std::invalid_argument);
  EXPECT_THROW(HeadingFactor(0.1, 0.0, Eigen::Quaterniond::Identity(), reference),
               std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
