#include "factors/dvl_factor.h"

#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include "auvdock/geometry/pose3.h"
#include "auvdock/imu/imu_preintegration.h"
#include "factors/pose_manifold.h"

namespace auvdock {
namespace {

const Eigen::Vector3d kGravity_D(0.0, 0.0, 9.81);

// The DVL mounted 45 degrees about z, 0.6 m ahead of and 0.2 m below the IMU.
Pose3 DvlMounting() {
  return Pose3(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 4.0, Eigen::Vector3d::UnitZ())),
               Eigen::Vector3d(0.6, 0.0, 0.2));
}

// A body turning at a constant rate w_B while its velocity changes at a constant a_D.
struct ConstantMotion {
  Eigen::Vector3d p0{1.0, -2.0, 3.0}, v0{0.4, -0.1, 0.05}, a_D{0.05, 0.02, -0.03};
  Eigen::Quaterniond q0 =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  Eigen::Vector3d w_B{0.1, -0.2, 0.3};

  Eigen::Quaterniond q(double t) const {
    return q0 * Eigen::Quaterniond(Eigen::AngleAxisd(w_B.norm() * t, w_B.normalized()));
  }
  Eigen::Vector3d v(double t) const { return v0 + a_D * t; }
  // What the DVL measures at t: v_S = R_S_B (R_B_D v_D + w_B x p_B_S).
  Eigen::Vector3d DvlVelocity(double t, const Pose3& T_B_S) const {
    return T_B_S.q.conjugate() * (q(t).conjugate() * v(t) + w_B.cross(T_B_S.p));
  }
};

ImuPoseShift ShiftFromImu(const ConstantMotion& m, double dt, int steps) {
  ImuPreintegration pim{ImuNoiseDensities(), ImuBias()};
  const double h = dt / steps;
  for (int k = 0; k < steps; ++k) {
    pim.Integrate(m.w_B, m.q((k + 0.5) * h).conjugate() * (m.a_D - kGravity_D), h);
  }
  ImuPoseShift shift;
  shift.dt_s = pim.sum_dt();
  shift.delta_q = pim.delta_q();
  shift.delta_p = pim.delta_p();
  shift.delta_v = pim.delta_v();
  shift.gravity_D = kGravity_D;
  return shift;
}

void SetStateBlocks(const ConstantMotion& m, double* pose, double* velocity) {
  PoseToBlock(Pose3(m.q0, m.p0), pose);
  for (int i = 0; i < 3; ++i) velocity[i] = m.v0[i];
}

// Known answer at the state's own time: the truth gives a zero residual, and 3 cm/s too fast
// along the DVL's x gives -3 sigma on that axis alone.
TEST(DvlFactorTest, ResidualIsTheWhitenedVelocityErrorInTheSensorFrame) {
  const ConstantMotion m;
  const Pose3 T_B_S = DvlMounting();
  double pose[kPoseSize], velocity[kVelocitySize];
  SetStateBlocks(m, pose, velocity);
  const Eigen::Vector3d v_S = m.DvlVelocity(0.0, T_B_S);
  double r[3];
  ASSERT_TRUE(DvlFactor(v_S, 0.01, T_B_S, m.w_B)(pose, velocity, r));
  EXPECT_LT(Eigen::Map<Eigen::Vector3d>(r).norm(), 1e-12);
  ASSERT_TRUE(DvlFactor(v_S + Eigen::Vector3d(0.03, 0, 0), 0.01, T_B_S, m.w_B)(pose, velocity, r));
  EXPECT_NEAR(r[0], -3.0, 1e-9);
  EXPECT_NEAR(r[1], 0.0, 1e-9);
  EXPECT_NEAR(r[2], 0.0, 1e-9);
}

// The lever arm: turning about z at 0.3 rad/s moves a DVL 0.6 m ahead sideways at 0.18 m/s.
TEST(DvlFactorTest, TheBodyRateMovesALeverArmedSensor) {
  const Pose3 T_B_S(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.6, 0.0, 0.0));
  double pose[kPoseSize], velocity[kVelocitySize] = {0.0, 0.0, 0.0};
  PoseToBlock(Pose3(), pose);
  double r[3];
  ASSERT_TRUE(DvlFactor(Eigen::Vector3d::Zero(), 1.0, T_B_S, Eigen::Vector3d(0, 0, 0.3))(
      pose, velocity, r));
  EXPECT_NEAR(r[0], 0.0, 1e-12);
  EXPECT_NEAR(r[1], 0.18, 1e-12);
  EXPECT_NEAR(r[2], 0.0, 1e-12);
}

// At a later time than the state: the IMU's shift carries the state's velocity to the sample's
// time (0.15 s later), where the truth again gives a zero residual; without the shift it does not.
TEST(DvlFactorTest, ASampleAfterTheStateIsMetThroughTheImuShift) {
  const ConstantMotion m;
  const Pose3 T_B_S = DvlMounting();
  double pose[kPoseSize], velocity[kVelocitySize];
  SetStateBlocks(m, pose, velocity);
  const double dt = 0.15;
  const Eigen::Vector3d v_S = m.DvlVelocity(dt, T_B_S);
  double r[3];
  ASSERT_TRUE(DvlFactor(v_S, 0.01, T_B_S, m.w_B, ShiftFromImu(m, dt, 3000))(pose, velocity, r));
  // m/s; what is left is the integration's first-order error in the turning body (~h)
  EXPECT_LT(Eigen::Map<Eigen::Vector3d>(r).norm() * 0.01, 1e-4);
  ASSERT_TRUE(DvlFactor(v_S, 0.01, T_B_S, m.w_B)(pose, velocity, r));
  EXPECT_GT(Eigen::Map<Eigen::Vector3d>(r).norm() * 0.01, 1e-3);
}

TEST(DvlFactorTest, JacobiansPassTheGradientCheckerWithThePoseManifold) {
  const ConstantMotion m;
  const Pose3 T_B_S = DvlMounting();
  std::unique_ptr<ceres::CostFunction> cost(DvlFactor::Create(
      m.DvlVelocity(0.1, T_B_S) + Eigen::Vector3d(0.02, -0.01, 0.03), 0.01, T_B_S, m.w_B,
      ShiftFromImu(m, 0.1, 50)));
  const PoseManifold manifold;
  std::vector<const ceres::Manifold*> manifolds = {&manifold, nullptr};
  const ceres::GradientChecker checker(cost.get(), &manifolds, ceres::NumericDiffOptions());
  double pose[kPoseSize], velocity[kVelocitySize];
  SetStateBlocks(m, pose, velocity);
  const double* parameters[2] = {pose, velocity};
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters, 1e-7, &results)) << results.error_log;
  // d r / d v_D = R_S_B R_Bt_D / sigma: a rotation over sigma, whatever the state.
  const Eigen::Matrix3d J_v = results.local_jacobians[1] * 0.01;
  EXPECT_LT((J_v * J_v.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-9);
  // The position does not enter a velocity.
  EXPECT_LT(results.local_jacobians[0].leftCols<3>().norm(), 1e-12);
}

// The DVL's bias: a measurement 2 cm/s too fast along the sensor's x is explained by a bias of
// (0.02, 0, 0) in S (zero residual), and a bias the measurement does not have shows as its own
// whitened error.
TEST(DvlFactorTest, ABiasInTheSensorFrameExplainsAMeasurementOffByIt) {
  const ConstantMotion m;
  const Pose3 T_B_S = DvlMounting();
  double pose[kPoseSize], velocity[kVelocitySize];
  SetStateBlocks(m, pose, velocity);
  const Eigen::Vector3d v_S = m.DvlVelocity(0.0, T_B_S);
  const DvlFactor factor(v_S + Eigen::Vector3d(0.02, 0.0, 0.0), 0.01, T_B_S, m.w_B);
  double r[3];
  const double bias[3] = {0.02, 0.0, 0.0};
  ASSERT_TRUE(factor(pose, velocity, bias, r));
  EXPECT_LT(Eigen::Map<Eigen::Vector3d>(r).norm(), 1e-12);
  const double other[3] = {0.02, 0.01, -0.03};
  ASSERT_TRUE(factor(pose, velocity, other, r));
  EXPECT_NEAR(r[0], 0.0, 1e-9);
  EXPECT_NEAR(r[1], 1.0, 1e-9);
  EXPECT_NEAR(r[2], -3.0, 1e-9);
}

TEST(DvlFactorTest, TheBiasedFactorsJacobiansPassTheGradientChecker) {
  const ConstantMotion m;
  const Pose3 T_B_S = DvlMounting();
  std::unique_ptr<ceres::CostFunction> cost(
      DvlFactor::CreateWithBias(m.DvlVelocity(0.1, T_B_S) + Eigen::Vector3d(0.02, -0.01, 0.03),
                                0.01, T_B_S, m.w_B, ShiftFromImu(m, 0.1, 50)));
  const PoseManifold manifold;
  std::vector<const ceres::Manifold*> manifolds = {&manifold, nullptr, nullptr};
  const ceres::GradientChecker checker(cost.get(), &manifolds, ceres::NumericDiffOptions());
  double pose[kPoseSize], velocity[kVelocitySize];
  SetStateBlocks(m, pose, velocity);
  const double bias[3] = {0.01, -0.02, 0.005};
  const double* parameters[3] = {pose, velocity, bias};
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters, 1e-7, &results)) << results.error_log;
  // d r / d b_S = I / sigma.
  EXPECT_LT((results.local_jacobians[2] * 0.01 - Eigen::Matrix3d::Identity()).norm(), 1e-9);
}

TEST(DvlFactorTest, RejectsBadInput) {
  const Pose3 T_B_S = DvlMounting();
  const Eigen::Vector3d w = Eigen::Vector3d::Zero();
  EXPECT_THROW(DvlFactor(Eigen::Vector3d(std::nan(""), 0, 0), 0.01, T_B_S, w),
               std::invalid_argument);
  EXPECT_THROW(DvlFactor(Eigen::Vector3d::Zero(), 0.0, T_B_S, w), std::invalid_argument);
  EXPECT_THROW(DvlFactor(Eigen::Vector3d::Zero(), 0.01, T_B_S, Eigen::Vector3d(INFINITY, 0, 0)),
               std::invalid_argument);
  ImuPoseShift backwards;
  backwards.dt_s = -0.1;
  EXPECT_THROW(DvlFactor(Eigen::Vector3d::Zero(), 0.01, T_B_S, w, backwards),
               std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
