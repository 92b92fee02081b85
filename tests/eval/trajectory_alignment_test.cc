#include "auvdock/eval/trajectory_alignment.h"

#include <random>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "auvdock/geometry/so3.h"
#include "auvdock/io/input_error.h"

namespace auvdock {
namespace {

using ::testing::HasSubstr;

std::vector<Eigen::Vector3d> RandomPoints(int n, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) points.emplace_back(u(*rng), u(*rng), u(*rng));
  return points;
}

Pose3 RandomPose(std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-30.0, 30.0);
  // Eigen's UnitRandom uses std::rand; build the rotation from the seeded generator instead.
  std::normal_distribution<double> g(0.0, 1.0);
  const Eigen::Quaterniond q(g(*rng), g(*rng), g(*rng), g(*rng));
  return Pose3(q.normalized(), Eigen::Vector3d(u(*rng), u(*rng), u(*rng)));
}

std::vector<Eigen::Vector3d> Transform(const Pose3& T, const std::vector<Eigen::Vector3d>& p) {
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector3d& x : p) out.push_back(T * x);
  return out;
}

void ExpectPoseNear(const Pose3& expected, const Pose3& actual, double tol) {
  EXPECT_LE((expected.Matrix() - actual.Matrix()).cwiseAbs().maxCoeff(), tol)
      << "expected\n"
      << expected.Matrix() << "\nactual\n"
      << actual.Matrix();
}

std::string AlignmentError(const std::vector<Eigen::Vector3d>& p_est,
                           const std::vector<Eigen::Vector3d>& p_true) {
  try {
    AlignPositionsSE3(p_est, p_true);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

TEST(AlignPositionsSE3Test, RecoversRandomTransforms) {
  std::mt19937 rng(12345);
  for (int trial = 0; trial < 20; ++trial) {
    const Pose3 T_true_est = RandomPose(&rng);
    const std::vector<Eigen::Vector3d> p_est = RandomPoints(3 + trial * 5, &rng);
    const Pose3 T_align = AlignPositionsSE3(p_est, Transform(T_true_est, p_est));
    ExpectPoseNear(T_true_est, T_align, 1e-9);
    EXPECT_NEAR(T_align.R().determinant(), 1.0, 1e-12);
  }
}

TEST(AlignPositionsSE3Test, IdentityForEqualPoints) {
  std::mt19937 rng(1);
  const std::vector<Eigen::Vector3d> p = RandomPoints(10, &rng);
  ExpectPoseNear(Pose3::Identity(), AlignPositionsSE3(p, p), 1e-12);
}

// Planar points (an AUV holding depth): rank 2 cross-covariance, and a mirror image fits the
// points as well as the rotation does -- the reflection fix must pick the rotation.
TEST(AlignPositionsSE3Test, RecoversTransformOfCoplanarPoints) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  std::vector<Eigen::Vector3d> p_est;
  for (int i = 0; i < 30; ++i) p_est.emplace_back(u(rng), u(rng), 5.0);
  for (int trial = 0; trial < 10; ++trial) {
    const Pose3 T_true_est = RandomPose(&rng);
    const Pose3 T_align = AlignPositionsSE3(p_est, Transform(T_true_est, p_est));
    ExpectPoseNear(T_true_est, T_align, 1e-9);
  }
}

// With noise, the result is the least-squares optimum: no small perturbation does better.
TEST(AlignPositionsSE3Test, IsLeastSquaresOptimalWithNoise) {
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.3);
  const Pose3 T_true_est = RandomPose(&rng);
  const std::vector<Eigen::Vector3d> p_est = RandomPoints(50, &rng);
  std::vector<Eigen::Vector3d> p_true = Transform(T_true_est, p_est);
  for (Eigen::Vector3d& p : p_true) p += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  const Pose3 T_align = AlignPositionsSE3(p_est, p_true);
  const auto cost = [&](const Pose3& T) {
    double c = 0.0;
    for (size_t i = 0; i < p_est.size(); ++i) c += (T * p_est[i] - p_true[i]).squaredNorm();
    return c;
  };
  const double best = cost(T_align);
  for (int k = 0; k < 6; ++k) {
    for (double sign : {-1.0, 1.0}) {
      Eigen::Matrix<double, 6, 1> xi = Eigen::Matrix<double, 6, 1>::Zero();
      xi(k) = sign * 1e-4;
      const Pose3 dT(ExpQuaternion(xi.head<3>()), xi.tail<3>());
      EXPECT_GE(cost(dT * T_align), best);
    }
  }
}

TEST(AlignPositionsSE3Test, RejectsTooFewPoints) {
  std::mt19937 rng(3);
  const std::vector<Eigen::Vector3d> p = RandomPoints(2, &rng);
  EXPECT_EQ(AlignmentError(p, p), "SE(3) alignment needs at least 3 non-collinear positions");
  EXPECT_THAT(AlignmentError({}, {}), HasSubstr("non-collinear"));
}

TEST(AlignPositionsSE3Test, RejectsCollinearPoints) {
  std::vector<Eigen::Vector3d> p_est;
  const Eigen::Vector3d origin(1.3, -2.1, 4.7);
  const Eigen::Vector3d direction = Eigen::Vector3d(0.3, -0.7, 0.2).normalized();
  for (int i = 0; i < 20; ++i) p_est.push_back(origin + 0.37 * i * direction);
  std::mt19937 rng(8);
  const std::vector<Eigen::Vector3d> p_true = Transform(RandomPose(&rng), p_est);
  EXPECT_EQ(AlignmentError(p_est, p_true),
            "SE(3) alignment needs at least 3 non-collinear positions");
  // All points equal.
  const std::vector<Eigen::Vector3d> same(5, origin);
  EXPECT_THAT(AlignmentError(same, same), HasSubstr("non-collinear"));
  // Non-collinear estimate against a collinear truth does not fix the rotation either.
  EXPECT_THAT(AlignmentError(RandomPoints(20, &rng), p_est), HasSubstr("non-collinear"));
}

}  // namespace
}  // namespace auvdock
