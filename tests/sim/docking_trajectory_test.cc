#include "auvdock/sim/docking_trajectory.h"

#include <gtest/gtest.h>

#include "auvdock/geometry/so3.h"
#include "auvdock/sim/smooth_scalar.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

TEST(Smooth, ProductAndSineRules) {
  // f(t) = t^2 sin(t): f' = 2t sin t + t^2 cos t, f'' = 2 sin t + 4 t cos t - t^2 sin t.
  const double t = 0.7;
  const Smooth T = Smooth::Time(t);
  const Smooth f = T * T * sin(T);
  EXPECT_NEAR(f.v, t * t * std::sin(t), 1e-15);
  EXPECT_NEAR(f.d, 2 * t * std::sin(t) + t * t * std::cos(t), 1e-15);
  EXPECT_NEAR(f.dd, 2 * std::sin(t) + 4 * t * std::cos(t) - t * t * std::sin(t), 1e-14);
}

TEST(Smooth, QuinticBlendBoundaryConditions) {
  const Smooth start = QuinticBlend(2.0, 2.0, 4.0, 1.0, 0.5, 3.0);
  EXPECT_DOUBLE_EQ(start.v, 1.0);
  EXPECT_NEAR(start.d, 0.5, 1e-15);
  EXPECT_NEAR(start.dd, 0.0, 1e-15);
  const Smooth end = QuinticBlend(6.0 - 1e-9, 2.0, 4.0, 1.0, 0.5, 3.0);
  EXPECT_NEAR(end.v, 3.0, 1e-9);
  EXPECT_NEAR(end.d, 0.0, 1e-8);
  EXPECT_NEAR(end.dd, 0.0, 1e-6);
}

class DockingTrajectoryTest : public ::testing::Test {
 protected:
  DockingTrajectory trajectory_{test::DefaultScenario().trajectory};
};

TEST_F(DockingTrajectoryTest, DerivativesMatchFiniteDifferences) {
  const double h = 1e-5;
  for (double t = 0.5; t < 39.5; t += 0.73) {
    const KinematicState s = trajectory_.At(t);
    const KinematicState a = trajectory_.At(t - h), b = trajectory_.At(t + h);
    const Eigen::Vector3d v_fd = (b.T_D_B.p - a.T_D_B.p) / (2 * h);
    const Eigen::Vector3d a_fd = (b.v_D - a.v_D) / (2 * h);
    EXPECT_LT((v_fd - s.v_D).norm(), 1e-8) << t;
    EXPECT_LT((a_fd - s.a_D).norm(), 1e-7) << t;
    // Body rate: R(t+h) = R(t) Exp(w_B h) to first order.
    const Eigen::Vector3d w_fd = LogQuaternion(a.T_D_B.q.conjugate() * b.T_D_B.q) / (2 * h);
    EXPECT_LT((w_fd - s.omega_B).norm(), 1e-7) << t;
  }
}

TEST_F(DockingTrajectoryTest, ApproachesFromBehindAndAboveAndLands) {
  const auto& c = trajectory_.config();
  const KinematicState start = trajectory_.At(0.0);
  EXPECT_LT(start.T_D_B.p.x(), -6.0);  // 6-10 m behind the dock
  EXPECT_GT(start.T_D_B.p.x(), -10.0);
  EXPECT_LT(start.T_D_B.p.z(), -2.0);  // above it
  const KinematicState landed = trajectory_.At(c.touchdown_s + 1.0);
  EXPECT_NEAR(landed.T_D_B.p.z(), c.landed_z_D, 1e-9);
  EXPECT_LT(landed.v_D.norm(), 1e-9);
  EXPECT_LT(landed.omega_B.norm(), 1e-9);
  double max_speed = 0.0;
  for (double t = 0.0; t <= 40.0; t += 0.01) {
    max_speed = std::max(max_speed, trajectory_.At(t).v_D.norm());
  }
  EXPECT_LE(max_speed, 1.0);  // 2 knots
  EXPECT_GT(max_speed, 0.3);
}

}  // namespace
}  // namespace auvdock
