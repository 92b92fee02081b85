#include "factors/depth_factor.h"
#include "factors/depth_offset_factor.h"

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

// A shift of 60 ms with some turn and motion of its own (not a real IMU's: any rigid shift).
ImuPoseShift SomeShift() {
  ImuPoseShift shift;
  shift.dt_s = 0.06;
  shift.delta_q = Eigen::Quaterniond(Eigen::AngleAxisd(0.02, Eigen::Vector3d(0.3, -1, 0.2).normalized()));
  shift.delta_p = Eigen::Vector3d(0.01, -0.004, 0.002);
  shift.delta_v = Eigen::Vector3d(0.02, 0.0, -0.01);
  shift.gravity_D = kDown;
  return shift;
}

// Known answer: a sensor reading b deeper than the survey's zero fits exactly with offset b; the
// residual moves by 1 / sigma per metre of offset; at the state's own time the velocity is unused.
TEST(DepthOffsetFactorTest, TheOffsetAddsToTheModelledDepth) {
  const Pose3 T_D_B = TiltedPose();
  const double true_depth = 30.0 + (T_D_B * kLeverArm).z();
  const DepthFactor biased(true_depth + 0.3, 0.02, 30.0, kDown, kLeverArm);
  const DepthOffsetFactor factor(biased, ImuPoseShift{0.0, Eigen::Quaterniond::Identity(),
                                                      Eigen::Vector3d::Zero(),
                                                      Eigen::Vector3d::Zero(), kDown});
  double pose[kPoseSize];
  PoseToBlock(T_D_B, pose);
  const double velocity[3] = {0.5, -0.2, 0.1};
  double r = 1.0;
  const double exact_offset = 0.3, no_offset = 0.0;
  ASSERT_TRUE(factor(pose, velocity, &exact_offset, &r));
  EXPECT_NEAR(r, 0.0, 1e-9);
  ASSERT_TRUE(factor(pose, velocity, &no_offset, &r));
  EXPECT_NEAR(r, -15.0, 1e-9);  // -0.3 / 0.02
}

// At another time than the state's, the depth is the shifted pose's (time_shifted_factor.h).
TEST(DepthOffsetFactorTest, ASampleAfterTheStateIsTakenAtTheShiftedPose) {
  const ImuPoseShift shift = SomeShift();
  double pose[kPoseSize], shifted[kPoseSize];
  PoseToBlock(TiltedPose(), pose);
  const double velocity[3] = {0.5, -0.2, 0.1};
  shift.Apply(pose, velocity, shifted);
  const DepthFactor depth(31.2, 0.02, 30.0, kDown, kLeverArm);
  const DepthOffsetFactor factor(depth, shift);
  double r_plain = 0.0, r_offset = 0.0;
  const double offset = 0.07;
  ASSERT_TRUE(depth(shifted, &r_plain));
  ASSERT_TRUE(factor(pose, velocity, &offset, &r_offset));
  EXPECT_NEAR(r_offset, r_plain + 0.07 / 0.02, 1e-9);
}

TEST(DepthOffsetFactorTest, JacobiansPassTheGradientCheckerWithThePoseManifold) {
  std::unique_ptr<ceres::CostFunction> cost(DepthOffsetFactor::Create(
      DepthFactor(31.7, 0.02, 30.0, kDown, kLeverArm), SomeShift()));
  const PoseManifold manifold;
  std::vector<const ceres::Manifold*> manifolds = {&manifold, nullptr, nullptr};
  const ceres::GradientChecker checker(cost.get(), &manifolds, ceres::NumericDiffOptions());
  double pose[kPoseSize];
  PoseToBlock(TiltedPose(), pose);
  double velocity[3] = {0.4, -0.1, 0.05};
  double offset[1] = {0.12};
  const double* parameters[3] = {pose, velocity, offset};
  ceres::GradientChecker::ProbeResults results;
  checker.Probe(parameters, 1e-7, &results);
  ASSERT_EQ(results.local_jacobians.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    // Absolute comparison, as for the depth factor: some entries are zeros.
    EXPECT_LT((results.local_jacobians[i] - results.local_numeric_jacobians[i]).cwiseAbs().maxCoeff(),
              1e-7)
        << results.error_log;
  }
  EXPECT_NEAR(results.local_jacobians[2](0, 0), 50.0, 1e-9);              // 1 / sigma
  EXPECT_NEAR(results.local_jacobians[1](0, 2), 50.0 * 0.06, 1e-9);       // dt / sigma along z
}

}  // namespace
}  // namespace auvdock
