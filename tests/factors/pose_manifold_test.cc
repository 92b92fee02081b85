#include "factors/pose_manifold.h"

#include <random>

#include <ceres/manifold_test_utils.h>
#include <gtest/gtest.h>

namespace auvdock {
namespace {

Eigen::Matrix<double, 7, 1> RandomPose(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Matrix<double, 7, 1> x;
  for (int i = 0; i < 3; ++i) x[i] = 3.0 * normal(rng);
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  x.tail<4>() = q.normalized().coeffs();
  return x;
}

Eigen::Matrix<double, 6, 1> RandomDelta(std::mt19937_64& rng, double scale) {
  std::normal_distribution<double> normal(0.0, scale);
  Eigen::Matrix<double, 6, 1> d;
  for (int i = 0; i < 6; ++i) d[i] = normal(rng);
  return d;
}

// Ceres' own manifold invariants: Plus(x, 0) = x, Minus(Plus(x, d), x) = d, the Jacobians agree
// with automatic differentiation of Plus/Minus, and MinusJacobian * PlusJacobian = I.
TEST(PoseManifoldTest, CeresInvariantsHoldAtIdentityNearIdentityAndRandomPoints) {
  using namespace ceres;  // NOLINT: the Ceres macro names its helpers unqualified
  const PoseManifold manifold;
  std::mt19937_64 rng(7);
  Eigen::Matrix<double, 7, 1> identity;
  identity << 0, 0, 0, 0, 0, 0, 1;
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Matrix<double, 7, 1> x = trial == 0 ? identity : RandomPose(rng);
    const Eigen::Matrix<double, 6, 1> delta = RandomDelta(rng, trial % 2 ? 1e-4 : 0.5);
    // y within half a turn of x: the quaternion double cover makes Plus(x, Minus(y, x)) equal
    // to y or -y (the same rotation) otherwise.
    Eigen::Matrix<double, 7, 1> y;
    manifold.Plus(x.data(), RandomDelta(rng, 0.8).data(), y.data());
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, 1e-9);
  }
}

TEST(PoseManifoldTest, RotationIsPerturbedOnTheLeftInTheDockFrame) {
  const PoseManifold manifold;
  double x[7] = {1.0, 2.0, 3.0, 0.0, 0.0, std::sin(0.25), std::cos(0.25)};  // yaw 0.5 rad
  const double delta[6] = {0.1, -0.2, 0.3, 0.0, 0.0, 0.2};                  // yaw 0.2 rad more
  double y[7];
  ASSERT_TRUE(manifold.Plus(x, delta, y));
  EXPECT_NEAR(y[0], 1.1, 1e-15);
  EXPECT_NEAR(y[1], 1.8, 1e-15);
  EXPECT_NEAR(y[2], 3.3, 1e-15);
  const Eigen::Map<const Eigen::Quaterniond> q(y + 3);
  const Eigen::AngleAxisd aa(q);
  EXPECT_NEAR(aa.angle(), 0.7, 1e-12);
  EXPECT_NEAR(aa.axis().z(), 1.0, 1e-12);

  // A roll step on a yawed pose is a rotation about the dock's x axis, not the body's.
  double pitched[7];
  const double roll_in_d[6] = {0, 0, 0, 0.3, 0, 0};
  ASSERT_TRUE(manifold.Plus(x, roll_in_d, pitched));
  const Eigen::Quaterniond expected =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX())) *
      Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  EXPECT_NEAR(Eigen::Map<const Eigen::Quaterniond>(pitched + 3).angularDistance(expected), 0.0,
              1e-12);
}

TEST(PoseManifoldTest, MinusTakesTheShorterOfQAndMinusQ) {
  const PoseManifold manifold;
  const double x[7] = {0, 0, 0, 0, 0, 0, 1};
  const double y[7] = {0, 0, 0, 0, 0, -std::sin(0.05), -std::cos(0.05)};  // -q of yaw 0.1
  double d[6];
  ASSERT_TRUE(manifold.Minus(y, x, d));
  EXPECT_NEAR(d[5], 0.1, 1e-12);
}

TEST(PoseManifoldTest, ExpAndLogAreInverseIncludingNearZeroAndNearPi) {
  for (const double angle : {0.0, 1e-12, 1e-7, 1e-3, 0.5, 2.0, 3.1415}) {
    const Eigen::Vector3d phi = angle * Eigen::Vector3d(0.48, -0.6, 0.64);
    const Eigen::Vector3d back = QuaternionLog<double>(QuaternionExp<double>(phi));
    EXPECT_NEAR((back - phi).norm(), 0.0, 1e-12 * std::max(1.0, angle)) << angle;
  }
}

}  // namespace
}  // namespace auvdock
