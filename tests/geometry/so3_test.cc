#include "auvdock/geometry/so3.h"

#include <random>

#include <gtest/gtest.h>

#include "auvdock/geometry/pose3.h"

namespace auvdock {
namespace {

TEST(So3, ExpLogRoundTripAtRandomAndExtremeAngles) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    for (double angle : {0.0, 1e-12, 1e-6, 0.3, 2.0, M_PI - 1e-6}) {
      const Eigen::Vector3d w = angle * axis;
      EXPECT_LT((LogQuaternion(ExpQuaternion(w)) - w).norm(), 1e-9) << angle;
    }
  }
}

TEST(So3, ExpMatchesAngleAxis) {
  const Eigen::Vector3d w(0.3, -0.2, 0.9);
  const Eigen::Matrix3d expected = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  EXPECT_LT((ExpSO3(w) - expected).norm(), 1e-14);
}

TEST(So3, HatIsCrossProduct) {
  const Eigen::Vector3d a(1.0, -2.0, 0.5), b(0.3, 0.7, -1.1);
  EXPECT_LT((Hat(a) * b - a.cross(b)).norm(), 1e-15);
}

TEST(So3, LogReturnsShortestRotation) {
  const Eigen::Quaterniond q = ExpQuaternion(Eigen::Vector3d(0.0, 0.0, 1.0));
  const Eigen::Quaterniond minus_q(-q.w(), -q.x(), -q.y(), -q.z());
  EXPECT_LT((LogQuaternion(minus_q) - Eigen::Vector3d(0.0, 0.0, 1.0)).norm(), 1e-12);
}

TEST(So3, RollPitchYawRoundTrip) {
  for (double roll : {-3.0, -0.4, 0.0, 0.7, 3.1}) {
    for (double pitch : {-1.5, -0.2, 0.0, 0.9, 1.5}) {
      for (double yaw : {-3.1, -1.0, 0.0, 2.0, 3.1}) {
        const Eigen::Vector3d rpy =
            RollPitchYawFromQuaternion(QuaternionFromRollPitchYaw(roll, pitch, yaw));
        EXPECT_NEAR(rpy.x(), roll, 1e-9);
        EXPECT_NEAR(rpy.y(), pitch, 1e-9);
        EXPECT_NEAR(rpy.z(), yaw, 1e-9);
      }
    }
  }
}

TEST(So3, WrapAngle) {
  EXPECT_NEAR(WrapAngle(3.0 * M_PI), M_PI, 1e-12);
  EXPECT_NEAR(WrapAngle(-M_PI / 2 - 2 * M_PI), -M_PI / 2, 1e-12);
  EXPECT_NEAR(WrapAngle(0.1), 0.1, 1e-15);
}

TEST(Pose3, ComposeInverseAndInterpolate) {
  const Pose3 T_A_B(ExpQuaternion(Eigen::Vector3d(0.1, 0.2, -0.3)), Eigen::Vector3d(1, 2, 3));
  const Pose3 T_B_C(ExpQuaternion(Eigen::Vector3d(-0.4, 0.0, 0.5)), Eigen::Vector3d(-1, 0, 2));
  const Eigen::Vector3d p_C(0.3, -0.7, 1.9);
  EXPECT_LT(((T_A_B * T_B_C) * p_C - T_A_B * (T_B_C * p_C)).norm(), 1e-14);
  const Pose3 I = T_A_B * T_A_B.Inverse();
  EXPECT_LT(I.p.norm(), 1e-14);
  EXPECT_LT(RotationAngleBetween(I.q, Eigen::Quaterniond::Identity()), 1e-7);
  EXPECT_LT((Pose3::FromMatrix(T_A_B.Matrix()).p - T_A_B.p).norm(), 1e-15);
  const Pose3 mid = Interpolate(Pose3(), T_A_B, 0.5);
  EXPECT_LT((mid.p - 0.5 * T_A_B.p).norm(), 1e-15);
  EXPECT_NEAR(RotationAngleBetween(Eigen::Quaterniond::Identity(), mid.q),
              0.5 * RotationAngleBetween(Eigen::Quaterniond::Identity(), T_A_B.q), 1e-12);
}

}  // namespace
}  // namespace auvdock
