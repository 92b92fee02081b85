#include "factors/time_shifted_factor.h"

#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>
#include <vector>

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include "auvdock/geometry/pose3.h"
#include "auvdock/imu/imu_preintegration.h"
#include "factors/pose_manifold.h"
#include "factors/stereo_point_factor.h"

namespace auvdock {
namespace {

const Eigen::Vector3d kGravity_D(0.0, 0.0, 9.81);

// A body turning at a constant rate w_B and moving with a constant acceleration a_D from
// (p0, v0, q0): the truth at t, and what its IMU measures (gyro w_B, specific force
// R_D_B^T (a_D - g_D)).
struct ConstantMotion {
  Eigen::Vector3d p0{1.0, -2.0, 3.0}, v0{0.4, -0.1, 0.05}, a_D{0.05, 0.02, -0.03};
  Eigen::Quaterniond q0 =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  Eigen::Vector3d w_B{0.1, -0.2, 0.3};

  Eigen::Quaterniond q(double t) const {
    return q0 * Eigen::Quaterniond(Eigen::AngleAxisd(w_B.norm() * t, w_B.normalized()));
  }
  Eigen::Vector3d p(double t) const { return p0 + v0 * t + 0.5 * a_D * t * t; }
};

ImuPoseShift ShiftFromImu(const ConstantMotion& m, double dt, int steps) {
  ImuPreintegration pim{ImuNoiseDensities(), ImuBias()};
  const double h = dt / steps;
  for (int k = 0; k < steps; ++k) {
    // The specific force at the middle of the step (the rotation changes within it).
    pim.Integrate(m.w_B, m.q((k + 0.5) * h).conjugate() * (m.a_D - kGravity_D), h);
  }
  ImuPoseShift shift;
  shift.dt_s = pim.sum_dt();
  shift.delta_q = pim.delta_q();
  shift.delta_p = pim.delta_p();
  shift.gravity_D = kGravity_D;
  return shift;
}

// A pose factor that returns its pose block's position and the vector part of its quaternion:
// it shows what pose the wrapped factor is evaluated at.
struct PoseEcho {
  template <typename T>
  bool operator()(const T* pose, T* residuals) const {
    for (int i = 0; i < 6; ++i) residuals[i] = pose[i];
    return true;
  }
};

TEST(TimeShiftedFactorTest, EvaluatesTheWrappedFactorAtTheImuPredictedPose) {
  const ConstantMotion m;
  const double dt = 0.05;
  const ImuPoseShift shift = ShiftFromImu(m, dt, 50);
  const TimeShiftedFactor<PoseEcho, 6> factor(std::make_unique<PoseEcho>(), shift);
  double pose[kPoseSize], velocity[3];
  PoseToBlock(Pose3(m.q0, m.p0), pose);
  Eigen::Map<Eigen::Vector3d> velocity_D(velocity);
  velocity_D = m.v0;
  double shifted[kPoseSize];
  factor.ShiftedPose(pose, velocity, shifted);
  const Pose3 T = PoseFromBlock(shifted);
  // To the held samples' step-size accuracy (1 ms steps: ~2 um over 50 ms).
  EXPECT_LT((T.p - m.p(dt)).norm(), 1e-5);
  EXPECT_LT(T.q.angularDistance(m.q(dt)), 1e-7);
  double residuals[6];
  ASSERT_TRUE(factor(pose, velocity, residuals));
  for (int i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(residuals[i], shifted[i]);
}

TEST(TimeShiftedFactorTest, ZeroShiftIsTheWrappedFactor) {
  const Eigen::Vector3d p_D_L(0.3, -0.2, 4.0);
  const Pose3 T_B_S(Eigen::Quaterniond(Eigen::AngleAxisd(0.8, Eigen::Vector3d::UnitY())),
                    Eigen::Vector3d(0.9, 0.1, 0.2));
  const Eigen::Matrix3d covariance = Eigen::Vector3d(1e-4, 2e-4, 9e-4).asDiagonal();
  const StereoPointFactor plain(Eigen::Vector3d(0.1, 0.2, 3.0), covariance, T_B_S, p_D_L);
  ImuPoseShift none;
  none.gravity_D = kGravity_D;
  const TimeShiftedFactor<StereoPointFactor, 3> wrapped(std::make_unique<StereoPointFactor>(plain),
                                                        none);
  double pose[kPoseSize];
  PoseToBlock(Pose3(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())),
                    Eigen::Vector3d(0.2, 0.1, 0.5)),
              pose);
  const double velocity[3] = {0.5, -0.3, 0.1};
  double r_plain[3], r_wrapped[3];
  ASSERT_TRUE(plain(pose, r_plain));
  ASSERT_TRUE(wrapped(pose, velocity, r_wrapped));
  for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(r_plain[i], r_wrapped[i]);
}

// The autodiff Jacobians on the pose (through PoseManifold) and the velocity agree with
// numerical ones: the velocity enters as dt times the identity on the position.
TEST(TimeShiftedFactorTest, JacobiansPassTheGradientChecker) {
  const ConstantMotion m;
  const ImuPoseShift shift = ShiftFromImu(m, 0.04, 8);
  const Eigen::Vector3d p_D_L(1.3, -1.6, 6.0);
  const Pose3 T_B_S(Eigen::Quaterniond(Eigen::AngleAxisd(0.8, Eigen::Vector3d::UnitY())),
                    Eigen::Vector3d(0.9, 0.1, 0.2));
  Eigen::Matrix3d covariance;
  covariance << 4e-4, 1e-5, 0.0, 1e-5, 3e-4, 2e-5, 0.0, 2e-5, 2e-3;
  std::unique_ptr<ceres::CostFunction> cost(TimeShiftedFactor<StereoPointFactor, 3>::Create(
      std::make_unique<StereoPointFactor>(Eigen::Vector3d(0.2, -0.1, 2.5), covariance, T_B_S,
                                          p_D_L),
      shift));
  const PoseManifold manifold;
  std::vector<const ceres::Manifold*> manifolds = {&manifold, nullptr};
  const ceres::GradientChecker checker(cost.get(), &manifolds, ceres::NumericDiffOptions());
  double pose[kPoseSize];
  PoseToBlock(Pose3(m.q0, m.p0), pose);
  double velocity[3] = {0.4, -0.1, 0.05};
  const double* parameters[2] = {pose, velocity};
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters, 1e-7, &results)) << results.error_log;
  // d(position at t + dt) / d(v) = dt I, seen through the point residual's rotation.
  EXPECT_GT(results.jacobians[1].norm(), 0.0);
}

using EchoShifted = TimeShiftedFactor<PoseEcho, 6>;

TEST(TimeShiftedFactorTest, RejectsANegativeOrNonFiniteShift) {
  ImuPoseShift shift;
  shift.dt_s = -0.01;
  EXPECT_THROW(EchoShifted(std::make_unique<PoseEcho>(), shift), std::invalid_argument);
  shift.dt_s = 0.01;
  shift.delta_p.x() = std::nan("");
  EXPECT_THROW(EchoShifted(std::make_unique<PoseEcho>(), shift), std::invalid_argument);
  EXPECT_THROW(EchoShifted(nullptr, ImuPoseShift()), std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
