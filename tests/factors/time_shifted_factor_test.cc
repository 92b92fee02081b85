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

// The IMU preintegrated over [t_from, t_to] (t_from < t_to) as the shift of a state at t_to back
// to t_from when backward, else of a state at t_from forward to t_to (the motion's times: the
// state is at 0).
ImuPoseShift ShiftFromImuOver(const ConstantMotion& m, double t_from, double t_to, int steps,
                              bool backward) {
  ImuPreintegration pim{ImuNoiseDensities(), ImuBias()};
  const double h = (t_to - t_from) / steps;
  for (int k = 0; k < steps; ++k) {
    // The specific force at the middle of the step (the rotation changes within it).
    pim.Integrate(m.w_B, m.q(t_from + (k + 0.5) * h).conjugate() * (m.a_D - kGravity_D), h);
  }
  ImuPoseShift shift;
  shift.dt_s = backward ? -pim.sum_dt() : pim.sum_dt();
  shift.delta_q = pim.delta_q();
  shift.delta_p = pim.delta_p();
  shift.delta_v = pim.delta_v();
  shift.gravity_D = kGravity_D;
  return shift;
}

ImuPoseShift ShiftFromImu(const ConstantMotion& m, double dt, int steps) {
  return ShiftFromImuOver(m, 0.0, dt, steps, false);
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

// A measurement 0.6 s before the state (a late acoustic fix): the shift solves the IMU's motion
// over [t, t_k] for the earlier pose and velocity.
TEST(TimeShiftedFactorTest, ABackwardShiftGivesThePoseAndVelocityBeforeTheState) {
  const ConstantMotion m;
  const double tau = 0.6;
  const ImuPoseShift shift = ShiftFromImuOver(m, -tau, 0.0, 600, true);
  ASSERT_LT(shift.dt_s, 0.0);
  const TimeShiftedFactor<PoseEcho, 6> factor(std::make_unique<PoseEcho>(), shift);
  double pose[kPoseSize], velocity[3], shifted[kPoseSize], v_shifted[3];
  PoseToBlock(Pose3(m.q0, m.p0), pose);
  Eigen::Map<Eigen::Vector3d> velocity_D(velocity);
  velocity_D = m.v0;
  factor.ShiftedPose(pose, velocity, shifted);
  shift.ApplyVelocity(pose, velocity, v_shifted);
  const Pose3 T = PoseFromBlock(shifted);
  // The forward shift over the same interval from the true earlier state: its error is the
  // preintegration's step-size error over 0.6 s (~0.3 mm), which the backward shift shares.
  const ImuPoseShift forward = ShiftFromImuOver(m, -tau, 0.0, 600, false);
  double earlier[kPoseSize], forward_pose[kPoseSize];
  PoseToBlock(Pose3(m.q(-tau), m.p(-tau)), earlier);
  const Eigen::Vector3d v_earlier = m.v0 - m.a_D * tau;
  forward.Apply(earlier, v_earlier.data(), forward_pose);
  const double step_error = (PoseFromBlock(forward_pose).p - m.p0).norm();
  EXPECT_LT(step_error, 1e-3);
  EXPECT_LT((T.p - m.p(-tau)).norm(), 2.0 * step_error + 1e-9);
  EXPECT_LT(T.q.angularDistance(m.q(-tau)), 1e-7);
  EXPECT_LT((Eigen::Map<const Eigen::Vector3d>(v_shifted) - v_earlier).norm(), 5.0 * step_error);
  // And the forward shift from the backward-shifted state returns to the state exactly.
  double back[kPoseSize];
  forward.Apply(shifted, v_shifted, back);
  EXPECT_LT((PoseFromBlock(back).p - m.p0).norm(), 1e-9);
  EXPECT_LT(PoseFromBlock(back).q.angularDistance(m.q0), 1e-9);
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
  for (const ImuPoseShift& shift :
       {ShiftFromImu(m, 0.04, 8), ShiftFromImuOver(m, -0.5, 0.0, 50, true)}) {
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
}

using EchoShifted = TimeShiftedFactor<PoseEcho, 6>;

TEST(TimeShiftedFactorTest, RejectsANonFiniteShift) {
  ImuPoseShift shift;
  shift.dt_s = std::nan("");
  EXPECT_THROW(EchoShifted(std::make_unique<PoseEcho>(), shift), std::invalid_argument);
  shift.dt_s = 0.01;
  shift.delta_p.x() = std::nan("");
  EXPECT_THROW(EchoShifted(std::make_unique<PoseEcho>(), shift), std::invalid_argument);
  EXPECT_THROW(EchoShifted(nullptr, ImuPoseShift()), std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
