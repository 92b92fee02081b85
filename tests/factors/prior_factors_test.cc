#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>
#include <vector>

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include "auvdock/geometry/pose3.h"
#include "factors/bias_prior_factor.h"
#include "factors/pose_manifold.h"
#include "factors/pose_prior_factor.h"
#include "factors/scalar_random_walk_factor.h"
#include "factors/vector_random_walk_factor.h"
#include "factors/velocity_prior_factor.h"

namespace auvdock {
namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector7 = Eigen::Matrix<double, 7, 1>;

Vector7 ToBlock(const Pose3& T) {
  Vector7 x;
  x << T.p, T.q.coeffs();
  return x;
}

Eigen::Quaterniond RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
}

// A well-conditioned, correlated covariance: A A^T + diag.
template <int N>
Eigen::Matrix<double, N, N> RandomCovariance(std::mt19937_64& rng, double scale) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix<double, N, N> A;
  for (int i = 0; i < N; ++i) {
    for (int j = 0; j < N; ++j) A(i, j) = n(rng);
  }
  return scale * (0.3 * A * A.transpose() + Eigen::Matrix<double, N, N>::Identity());
}

void ExpectGradientCheckPasses(const ceres::CostFunction& cost, const double* x,
                               const ceres::Manifold* manifold) {
  std::vector<const ceres::Manifold*> manifolds = {manifold};
  const double* params[1] = {x};
  ceres::GradientChecker checker(&cost, &manifolds, ceres::NumericDiffOptions());
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(params, 1e-7, &results)) << results.error_log;
}

// Prior means at identity, near identity and random; the evaluation point is a tangent step
// away (none for the first, so the residual is zero there).
TEST(PosePriorFactorTest, ZeroAtTheMeanAndTangentStepGivesSqrtInfoTimesStep) {
  std::mt19937_64 rng(23);
  const PoseManifold manifold;
  std::normal_distribution<double> n(0.0, 1.0);
  const std::vector<Pose3> means = {Pose3::Identity(),
                                    Pose3(QuaternionExp<double>(Eigen::Vector3d(-1e-3, 2e-3, 1e-3)),
                                          Eigen::Vector3d(1e-3, 0, -2e-3)),
                                    Pose3(RandomRotation(rng), Eigen::Vector3d(1.0, -2.0, 3.0)),
                                    Pose3(RandomRotation(rng), Eigen::Vector3d(-4.0, 0.5, -1.0))};
  for (const Pose3& mean : means) {
    const Matrix6 covariance = RandomCovariance<6>(rng, 0.01);
    const PosePriorFactor factor(mean, covariance);
    const Vector7 x0 = ToBlock(mean);
    Vector6 r;
    ASSERT_TRUE(factor(x0.data(), r.data()));
    EXPECT_NEAR(r.norm(), 0.0, 1e-12);

    Vector6 delta;
    for (int i = 0; i < 6; ++i) delta[i] = 0.4 * n(rng);
    Vector7 x;
    ASSERT_TRUE(manifold.Plus(x0.data(), delta.data(), x.data()));
    EXPECT_NEAR((factor.UnweightedError(x.data()) - delta).norm(), 0.0, 1e-12);
    ASSERT_TRUE(factor(x.data(), r.data()));
    EXPECT_NEAR((r - factor.sqrt_information() * delta).norm(), 0.0, 1e-10);
    EXPECT_NEAR(factor.SquaredMahalanobis(x.data()), delta.dot(covariance.inverse() * delta), 1e-8);
    // The stored quaternion's sign does not matter.
    Vector7 x_flipped = x;
    x_flipped.tail<4>() *= -1.0;
    EXPECT_NEAR((factor.UnweightedError(x_flipped.data()) - delta).norm(), 0.0, 1e-12);
  }
}

TEST(PosePriorFactorTest, JacobiansPassTheGradientCheckerWithThePoseManifold) {
  std::mt19937_64 rng(29);
  const PoseManifold manifold;
  const std::vector<Pose3> means = {
      Pose3::Identity(),
      Pose3(QuaternionExp<double>(Eigen::Vector3d(1e-3, 1e-3, -2e-3)), Eigen::Vector3d(1e-3, 0, 0)),
      Pose3(RandomRotation(rng), Eigen::Vector3d(0.5, 1.0, -2.0))};
  // 1 mrad and 0.4 rad from the mean. At the mean itself J = sqrt_info, lower triangular, and the
  // checker would compare its exact zeros as round-off against round-off; that point (and the
  // Taylor branch of Log) is checked exactly in TangentJacobianAtTheMeanIsTheSqrtInformation.
  // The error angle must stay clear of pi, where Log(q q0^-1) jumps from the q to the -q side.
  const std::vector<Eigen::Vector3d> steps = {Eigen::Vector3d(1e-3, -2e-3, 1e-3),
                                              Eigen::Vector3d(0.2, -0.1, 0.33)};
  for (const Pose3& mean : means) {
    std::unique_ptr<ceres::CostFunction> cost(
        PosePriorFactor::Create(mean, RandomCovariance<6>(rng, 0.02)));
    for (const Eigen::Vector3d& dtheta : steps) {
      const Pose3 T(QuaternionExp<double>(dtheta) * mean.q, mean.p + 100.0 * dtheta.cwiseAbs());
      const Vector7 x = ToBlock(T);
      ExpectGradientCheckPasses(*cost, x.data(), &manifold);
    }
  }
}

// At the mean, d r / d delta = sqrt_info (MinusJacobian * PlusJacobian = I).
TEST(PosePriorFactorTest, TangentJacobianAtTheMeanIsTheSqrtInformation) {
  std::mt19937_64 rng(31);
  const PoseManifold manifold;
  const Pose3 mean(RandomRotation(rng), Eigen::Vector3d(0.2, -0.3, 1.0));
  const Matrix6 covariance = RandomCovariance<6>(rng, 0.05);
  std::unique_ptr<ceres::CostFunction> cost(PosePriorFactor::Create(mean, covariance));
  const Vector7 x = ToBlock(mean);
  const double* params[1] = {x.data()};
  Vector6 r;
  Eigen::Matrix<double, 6, 7, Eigen::RowMajor> J_r_x;
  double* jacobians[1] = {J_r_x.data()};
  ASSERT_TRUE(cost->Evaluate(params, r.data(), jacobians));
  Eigen::Matrix<double, 7, 6, Eigen::RowMajor> J_x_delta;
  ASSERT_TRUE(manifold.PlusJacobian(x.data(), J_x_delta.data()));
  const PosePriorFactor factor(mean, covariance);
  EXPECT_NEAR((J_r_x * J_x_delta - factor.sqrt_information()).norm(), 0.0, 1e-10);
}

TEST(VelocityPriorFactorTest, ZeroAtTheMeanOffsetGivesSqrtInfoTimesOffsetAndGradientsCheck) {
  std::mt19937_64 rng(37);
  const Eigen::Vector3d v0(0.5, -0.1, 0.05);
  const Eigen::Matrix3d covariance = RandomCovariance<3>(rng, 0.01);
  const VelocityPriorFactor factor(v0, covariance);
  Eigen::Vector3d r;
  ASSERT_TRUE(factor(v0.data(), r.data()));
  EXPECT_NEAR(r.norm(), 0.0, 1e-15);
  const Eigen::Vector3d d(0.02, -0.03, 0.01);
  const Eigen::Vector3d v = v0 + d;
  ASSERT_TRUE(factor(v.data(), r.data()));
  EXPECT_NEAR((r - factor.sqrt_information() * d).norm(), 0.0, 1e-12);
  EXPECT_NEAR((factor.UnweightedError(v.data()) - d).norm(), 0.0, 1e-15);
  EXPECT_NEAR(factor.SquaredMahalanobis(v.data()), d.dot(covariance.inverse() * d), 1e-9);
  const Eigen::Matrix3d S = factor.sqrt_information();
  EXPECT_NEAR((S.transpose() * S - covariance.inverse()).norm(), 0.0, 1e-9);

  std::unique_ptr<ceres::CostFunction> cost(VelocityPriorFactor::Create(v0, covariance));
  for (const Eigen::Vector3d& at : {Eigen::Vector3d::Zero().eval(), Eigen::Vector3d(1e-4, 0, -1e-4),
                                    Eigen::Vector3d(2, -1, 3)}) {
    ExpectGradientCheckPasses(*cost, at.data(), nullptr);
  }
}

TEST(BiasPriorFactorTest, ZeroAtTheMeanOffsetGivesSqrtInfoTimesOffsetAndGradientsCheck) {
  std::mt19937_64 rng(41);
  Vector6 b0;
  b0 << 1e-3, -2e-3, 5e-4, 0.05, -0.02, 0.1;
  Matrix6 covariance = Matrix6::Zero();
  covariance.diagonal() << 1e-6, 1e-6, 1e-6, 4e-3, 4e-3, 4e-3;
  const BiasPriorFactor factor(b0, covariance);
  Vector6 r;
  ASSERT_TRUE(factor(b0.data(), r.data()));
  EXPECT_NEAR(r.norm(), 0.0, 1e-15);
  // One sigma on every axis: residual of ones, Mahalanobis 6.
  Vector6 d;
  d << 1e-3, -1e-3, 1e-3, std::sqrt(4e-3), -std::sqrt(4e-3), std::sqrt(4e-3);
  const Vector6 b = b0 + d;
  ASSERT_TRUE(factor(b.data(), r.data()));
  EXPECT_NEAR((r.cwiseAbs() - Vector6::Ones()).norm(), 0.0, 1e-9);
  EXPECT_NEAR((r - factor.sqrt_information() * d).norm(), 0.0, 1e-12);
  EXPECT_NEAR(factor.SquaredMahalanobis(b.data()), 6.0, 1e-8);
  EXPECT_NEAR((factor.UnweightedError(b.data()) - d).norm(), 0.0, 1e-15);

  std::unique_ptr<ceres::CostFunction> cost(
      BiasPriorFactor::Create(b0, RandomCovariance<6>(rng, 1e-3)));
  Vector6 random_point;
  random_point << 0.01, -0.02, 0.03, 0.2, -0.1, 0.3;
  for (const Vector6& at : {Vector6::Zero().eval(), b0, random_point}) {
    ExpectGradientCheckPasses(*cost, at.data(), nullptr);
  }
}

TEST(PriorFactorsTest, RejectInvalidCovariancesAndMeans) {
  Matrix6 not_pd = Matrix6::Identity();
  not_pd(3, 3) = -1.0;
  EXPECT_THROW(PosePriorFactor(Pose3::Identity(), not_pd), std::invalid_argument);
  EXPECT_THROW(BiasPriorFactor(Vector6::Zero(), not_pd), std::invalid_argument);
  Eigen::Matrix3d asymmetric = Eigen::Matrix3d::Identity();
  asymmetric(2, 0) = 0.5;
  EXPECT_THROW(VelocityPriorFactor(Eigen::Vector3d::Zero(), asymmetric), std::invalid_argument);
  EXPECT_THROW(VelocityPriorFactor(Eigen::Vector3d(0, 0, INFINITY), Eigen::Matrix3d::Identity()),
               std::invalid_argument);
  Pose3 bad;
  bad.p.x() = std::nan("");
  EXPECT_THROW(PosePriorFactor(bad, Matrix6::Identity()), std::invalid_argument);
}

TEST(ScalarRandomWalkFactorTest, KnownAnswersAndBadInput) {
  const ScalarRandomWalkFactor walk(0.001, 4.0);  // sigma 0.002 over 4 s
  EXPECT_DOUBLE_EQ(walk.sigma(), 0.002);
  const double a = 0.1, b = 0.104;
  double r = 0.0;
  ASSERT_TRUE(walk(&a, &b, &r));
  EXPECT_NEAR(r, 2.0, 1e-12);
  const ScalarPriorFactor prior(0.0, 0.5);
  ASSERT_TRUE(prior(&b, &r));
  EXPECT_NEAR(r, 0.208, 1e-12);
  EXPECT_THROW(ScalarRandomWalkFactor(0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(ScalarRandomWalkFactor(0.001, 0.0), std::invalid_argument);
  EXPECT_THROW(ScalarRandomWalkFactor(std::nan(""), 1.0), std::invalid_argument);
  EXPECT_THROW(ScalarPriorFactor(std::nan(""), 1.0), std::invalid_argument);
  EXPECT_THROW(ScalarPriorFactor(0.0, -1.0), std::invalid_argument);
}

TEST(VectorRandomWalkFactorTest, KnownAnswersAndBadInput) {
  const VectorRandomWalkFactor walk(0.001, 4.0);  // sigma 0.002 per axis over 4 s
  EXPECT_DOUBLE_EQ(walk.sigma(), 0.002);
  const double a[3] = {0.1, -0.2, 0.0}, b[3] = {0.104, -0.201, 0.0};
  double r[3];
  ASSERT_TRUE(walk(a, b, r));
  EXPECT_NEAR(r[0], 2.0, 1e-12);
  EXPECT_NEAR(r[1], -0.5, 1e-12);
  EXPECT_NEAR(r[2], 0.0, 1e-12);
  const VectorPriorFactor prior(Eigen::Vector3d(0.1, 0.0, 0.0), 0.5);
  ASSERT_TRUE(prior(b, r));
  EXPECT_NEAR(r[0], 0.008, 1e-12);
  EXPECT_NEAR(r[1], -0.402, 1e-12);
  EXPECT_NEAR(r[2], 0.0, 1e-12);
  EXPECT_THROW(VectorRandomWalkFactor(0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(VectorRandomWalkFactor(0.001, -1.0), std::invalid_argument);
  EXPECT_THROW(VectorPriorFactor(Eigen::Vector3d(std::nan(""), 0, 0), 1.0), std::invalid_argument);
  EXPECT_THROW(VectorPriorFactor(Eigen::Vector3d::Zero(), 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
