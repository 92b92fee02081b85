#include "auvdock/vision/point_set_alignment.h"

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/SVD>

#include "auvdock/geometry/so3.h"

namespace auvdock {
namespace {

Pose3 RandomPose(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Pose3(ExpQuaternion(Eigen::Vector3d(n(rng), n(rng), n(rng))),
               Eigen::Vector3d(n(rng), n(rng), n(rng)) * 3.0);
}

std::vector<Eigen::Vector3d> RandomPoints(std::mt19937& rng, int n, bool coplanar) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) points.emplace_back(u(rng), u(rng), coplanar ? 0.0 : u(rng));
  return points;
}

std::vector<Eigen::Vector3d> Transform(const Pose3& T, const std::vector<Eigen::Vector3d>& p) {
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector3d& x : p) out.push_back(T * x);
  return out;
}

// The seed 004 / default T-shaped dock, z = 0 (coplanar).
std::vector<Eigen::Vector3d> TDock() {
  return {{-0.75, 0.0, 0.0}, {-0.25, 0.0, 0.0}, {0.25, 0.0, 0.0},
          {0.75, -0.6, 0.0}, {0.75, 0.0, 0.0},  {0.75, 0.6, 0.0}};
}

TEST(AlignPointSets, RecoversAKnownTransformExactly) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    for (bool coplanar : {false, true}) {
      const Pose3 T = RandomPose(rng);
      const auto src = RandomPoints(rng, 3 + trial % 8, coplanar);
      const AlignmentResult result = AlignPointSets(src, Transform(T, src));
      ASSERT_TRUE(result.ok) << result.reason;
      EXPECT_LT(RotationAngleBetween(result.T_dst_src.q, T.q), 1e-10);
      EXPECT_LT((result.T_dst_src.p - T.p).norm(), 1e-10);
      EXPECT_LT(result.rms_m, 1e-10);
      EXPECT_NEAR(result.T_dst_src.R().determinant(), 1.0, 1e-12);
    }
  }
}

TEST(AlignPointSets, CoplanarDockLightsAtManyAttitudes) {
  // Coplanar points: H has rank 2 and the sign of its third singular vectors is arbitrary, so
  // the naive V U^T is a reflection about half of the time; the fix must always recover R.
  std::mt19937 rng(11);
  int naive_reflections = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Pose3 T = RandomPose(rng);
    const auto src = TDock();
    const auto dst = Transform(T, src);
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d p0 = Eigen::Vector3d::Zero(), q0 = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < src.size(); ++i) {
      p0 += src[i] / src.size();
      q0 += dst[i] / src.size();
    }
    for (size_t i = 0; i < src.size(); ++i) H += (src[i] - p0) * (dst[i] - q0).transpose();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
    if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0) ++naive_reflections;

    const AlignmentResult result = AlignPointSets(src, dst);
    ASSERT_TRUE(result.ok) << result.reason;
    EXPECT_LT(RotationAngleBetween(result.T_dst_src.q, T.q), 1e-10);
    EXPECT_LT((result.T_dst_src.p - T.p).norm(), 1e-10);
  }
  std::printf("naive V U^T was a reflection in %d of 200 coplanar cases\n", naive_reflections);
}

TEST(AlignPointSets, ReflectionFixGivesTheBestRotationForAMirroredSet) {
  // dst = mirror image of src: the best orthogonal fit is the mirror (det V U^T = -1 exactly,
  // since H = S M with S symmetric, M = diag(1, 1, -1)); the answer must be the best rotation.
  std::mt19937 rng(3);
  const auto src = RandomPoints(rng, 10, false);
  std::vector<Eigen::Vector3d> dst;
  for (const Eigen::Vector3d& p : src) dst.emplace_back(p.x(), p.y(), -p.z());

  Eigen::Vector3d p0 = Eigen::Vector3d::Zero(), q0 = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < src.size(); ++i) {
    p0 += src[i] / src.size();
    q0 += dst[i] / src.size();
  }
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  double sum_squares = 0.0;
  for (size_t i = 0; i < src.size(); ++i) {
    H += (src[i] - p0) * (dst[i] - q0).transpose();
    sum_squares += (src[i] - p0).squaredNorm() + (dst[i] - q0).squaredNorm();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  ASSERT_LT((svd.matrixV() * svd.matrixU().transpose()).determinant(), 0.0);

  const AlignmentResult result = AlignPointSets(src, dst);
  ASSERT_TRUE(result.ok) << result.reason;
  const Eigen::Matrix3d R = result.T_dst_src.R();
  EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
  // Minimum over rotations of sum |R p - q|^2 = sum |p|^2 + |q|^2 - 2 (s1 + s2 - s3).
  const Eigen::Vector3d s = svd.singularValues();
  const double best_cost = sum_squares - 2.0 * (s(0) + s(1) - s(2));
  const double n = static_cast<double>(src.size());
  EXPECT_NEAR(result.rms_m * result.rms_m * n, best_cost, 1e-10);
  // And no nearby rotation does better.
  auto cost = [&](const Pose3& T) {
    double c = 0.0;
    for (size_t i = 0; i < src.size(); ++i) c += (T * src[i] - dst[i]).squaredNorm();
    return c;
  };
  std::normal_distribution<double> noise(0.0, 0.05);
  for (int k = 0; k < 100; ++k) {
    Pose3 perturbed = result.T_dst_src;
    perturbed.q = ExpQuaternion(Eigen::Vector3d(noise(rng), noise(rng), noise(rng))) * perturbed.q;
    perturbed.p = q0 - perturbed.R() * p0;
    EXPECT_GE(cost(perturbed), cost(result.T_dst_src) - 1e-12);
  }
}

TEST(AlignPointSets, WeightsActLikeRepeatedPointsAndZeroWeightDropsAnOutlier) {
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.01);
  const Pose3 T = RandomPose(rng);
  auto src = RandomPoints(rng, 8, false);
  auto dst = Transform(T, src);
  for (Eigen::Vector3d& q : dst) q += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));

  // Weight 2 == the point listed twice.
  std::vector<double> weights(src.size(), 1.0);
  weights[2] = 2.0;
  auto src_repeated = src, dst_repeated = dst;
  src_repeated.push_back(src[2]);
  dst_repeated.push_back(dst[2]);
  const AlignmentResult weighted = AlignPointSets(src, dst, weights);
  const AlignmentResult repeated = AlignPointSets(src_repeated, dst_repeated);
  ASSERT_TRUE(weighted.ok && repeated.ok);
  EXPECT_LT(RotationAngleBetween(weighted.T_dst_src.q, repeated.T_dst_src.q), 1e-12);
  EXPECT_LT((weighted.T_dst_src.p - repeated.T_dst_src.p).norm(), 1e-12);
  EXPECT_NEAR(weighted.rms_m, repeated.rms_m, 1e-12);

  // A gross outlier with weight 0 has no influence; scaling all weights changes nothing.
  auto clean_dst = Transform(T, src);
  clean_dst[4] += Eigen::Vector3d(5.0, -3.0, 2.0);
  std::vector<double> drop(src.size(), 3.0);
  drop[4] = 0.0;
  const AlignmentResult robust = AlignPointSets(src, clean_dst, drop);
  ASSERT_TRUE(robust.ok) << robust.reason;
  EXPECT_LT(RotationAngleBetween(robust.T_dst_src.q, T.q), 1e-10);
  EXPECT_LT((robust.T_dst_src.p - T.p).norm(), 1e-10);
  EXPECT_LT(robust.rms_m, 1e-10);
}

TEST(AlignPointSets, NoisyPointsGiveRmsAtTheNoiseLevel) {
  std::mt19937 rng(9);
  std::normal_distribution<double> noise(0.0, 0.01);
  const Pose3 T = RandomPose(rng);
  const auto src = RandomPoints(rng, 400, false);
  auto dst = Transform(T, src);
  for (Eigen::Vector3d& q : dst) q += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  const AlignmentResult result = AlignPointSets(src, dst);
  ASSERT_TRUE(result.ok);
  // 3 coordinates of sigma 0.01, minus the 6 fitted parameters.
  EXPECT_NEAR(result.rms_m, 0.01 * std::sqrt(3.0 * (400 - 2) / 400.0), 0.001);
  EXPECT_LT(RotationAngleBetween(result.T_dst_src.q, T.q), 0.003);
}

TEST(AlignPointSets, BadInputsAreReportedNotGuessed) {
  const std::vector<Eigen::Vector3d> three = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<Eigen::Vector3d> two = {{0, 0, 0}, {1, 0, 0}};
  const std::vector<Eigen::Vector3d> line = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {-3, -3, -3}};
  const std::vector<Eigen::Vector3d> same = {{1, 2, 3}, {1, 2, 3}, {1, 2, 3}};
  auto with = [](std::vector<Eigen::Vector3d> p, double value) {
    p[1].y() = value;
    return p;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();

  struct Case {
    const char* name;
    AlignmentResult result;
  };
  const Case cases[] = {
      {"two points", AlignPointSets(two, two)},
      {"empty", AlignPointSets({}, {})},
      {"size mismatch", AlignPointSets(three, two)},
      {"NaN in src", AlignPointSets(with(three, nan), three)},
      {"Inf in dst", AlignPointSets(three, with(three, inf))},
      {"collinear", AlignPointSets(line, line)},
      {"coincident", AlignPointSets(same, same)},
      {"weights size", AlignPointSets(three, three, {1.0, 1.0})},
      {"negative weight", AlignPointSets(three, three, {1.0, -1.0, 1.0})},
      {"NaN weight", AlignPointSets(three, three, {1.0, nan, 1.0})},
      {"two positive weights", AlignPointSets(three, three, {1.0, 0.0, 1.0})},
  };
  for (const Case& c : cases) {
    EXPECT_FALSE(c.result.ok) << c.name;
    EXPECT_FALSE(c.result.reason.empty()) << c.name;
  }
  // Nearly collinear but well above round-off is still solvable.
  std::vector<Eigen::Vector3d> thin = line;
  thin.emplace_back(0.0, 1e-3, 0.0);
  EXPECT_TRUE(AlignPointSets(thin, thin).ok);
}

}  // namespace
}  // namespace auvdock
