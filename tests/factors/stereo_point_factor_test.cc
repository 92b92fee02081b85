#include "factors/stereo_point_factor.h"

#include <memory>
#include <random>
#include <vector>

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include "auvdock/geometry/pose3.h"
#include "factors/pose_manifold.h"
#include "tests/testing/tangent_jacobian_check.h"

namespace auvdock {
namespace {

using Vector7 = Eigen::Matrix<double, 7, 1>;

Vector7 ToBlock(const Pose3& T) {
  Vector7 x;
  x << T.p, T.q.coeffs();
  return x;
}

Pose3 FromBlock(const Vector7& x) {
  return Pose3(Eigen::Quaterniond(x[6], x[3], x[4], x[5]), x.head<3>());
}

Eigen::Quaterniond RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
}

// Forward-down stereo-left camera: optical axis forward and 30 degrees down, image x = body y,
// with a 3 degree mounting roll about the optical axis (so that no Jacobian entry is exactly zero
// and compared as round-off against round-off).
Pose3 ForwardDownExtrinsic() {
  Eigen::Matrix3d R_B_C;  // columns: camera x, y, z in B for a camera looking straight forward
  R_B_C << 0, 0, 1,       //
      1, 0, 0,            //
      0, 1, 0;
  const Eigen::Quaterniond pitch_down(Eigen::AngleAxisd(-0.5236, Eigen::Vector3d::UnitY()));
  const Eigen::Quaterniond roll(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitZ()));  // in C
  return Pose3(pitch_down * Eigen::Quaterniond(R_B_C) * roll, Eigen::Vector3d(0.6, -0.1, 0.15));
}

// A stereo-like covariance in S: lateral sigma 1 cm, depth (z) sigma 8 cm, slightly correlated.
Eigen::Matrix3d StereoCovariance() {
  Eigen::Matrix3d sqrt_cov;
  sqrt_cov << 0.01, 0.0, 0.0,  //
      0.001, 0.012, 0.0,       //
      0.02, -0.01, 0.08;
  return sqrt_cov * sqrt_cov.transpose();
}

std::vector<Pose3> TestPoses() {
  std::mt19937_64 rng(17);
  std::vector<Pose3> poses = {Pose3::Identity(),
                              Pose3(QuaternionExp<double>(Eigen::Vector3d(1e-3, -5e-4, 2e-3)),
                                    Eigen::Vector3d(2e-3, 1e-3, -1e-3))};
  std::normal_distribution<double> n(0.0, 2.0);
  for (int i = 0; i < 4; ++i) {
    poses.emplace_back(RandomRotation(rng), Eigen::Vector3d(n(rng), n(rng), n(rng)));
  }
  return poses;
}

TEST(StereoPointFactorTest, PerfectMeasurementGivesZeroResidual) {
  const Pose3 T_B_S = ForwardDownExtrinsic();
  const Eigen::Vector3d p_S(0.3, -0.2, 3.0);
  for (const Pose3& T_D_B : TestPoses()) {
    const Eigen::Vector3d p_D_L = T_D_B * (T_B_S * p_S);
    const StereoPointFactor factor(p_S, StereoCovariance(), T_B_S, p_D_L);
    const Vector7 x = ToBlock(T_D_B);
    double r[3];
    ASSERT_TRUE(factor(x.data(), r));
    EXPECT_NEAR(Eigen::Vector3d(r[0], r[1], r[2]).norm(), 0.0, 1e-9);
    EXPECT_NEAR(factor.SquaredMahalanobis(x.data()), 0.0, 1e-16);
    // The prediction equals (T_D_B T_B_S)^-1 p_D_L through Pose3.
    EXPECT_NEAR((factor.PredictedPointInS(x.data()) - (T_D_B * T_B_S).Inverse() * p_D_L).norm(),
                0.0, 1e-12);
  }
}

TEST(StereoPointFactorTest, JacobiansPassTheGradientCheckerWithThePoseManifold) {
  const Pose3 T_B_S = ForwardDownExtrinsic();
  const PoseManifold manifold;
  std::vector<const ceres::Manifold*> manifolds = {&manifold};
  for (const Pose3& T_D_B : TestPoses()) {
    const Eigen::Vector3d p_S_true(-0.4, 0.25, 2.5);
    const Eigen::Vector3d p_D_L = T_D_B * (T_B_S * p_S_true);
    const Eigen::Vector3d p_S = p_S_true + Eigen::Vector3d(0.02, -0.01, 0.1);
    std::unique_ptr<ceres::CostFunction> cost(
        StereoPointFactor::Create(p_S, StereoCovariance(), T_B_S, p_D_L, 1.5));
    const Vector7 x = ToBlock(T_D_B);
    const double* params[1] = {x.data()};
    ceres::NumericDiffOptions numeric;
    numeric.ridders_relative_initial_step_size = 1e-3;  // as in the mono test
    ceres::GradientChecker checker(cost.get(), &manifolds, numeric);
    ceres::GradientChecker::ProbeResults results;
    EXPECT_TRUE(checker.Probe(params, 1e-7, &results)) << results.error_log;
  }
}

// The analytic Jacobian (Create) against ceres::Jet's (CreateAutoDiff) in the tangent space
// (ambient Jacobian times the manifold's PlusJacobian); and the residuals equal
// (tests/testing/tangent_jacobian_check.h).
TEST(StereoPointFactorTest, AnalyticJacobianEqualsAutomaticDifferentiation) {
  const Pose3 T_B_S = ForwardDownExtrinsic();
  for (const Pose3& T_D_B : TestPoses()) {
    const Eigen::Vector3d p_S_true(-0.4, 0.25, 2.5);
    const Eigen::Vector3d p_D_L = T_D_B * (T_B_S * p_S_true);
    const Eigen::Vector3d p_S = p_S_true + Eigen::Vector3d(0.02, -0.01, 0.1);
    std::unique_ptr<ceres::CostFunction> analytic(StereoPointFactor::Create(
        std::make_unique<StereoPointFactor>(p_S, StereoCovariance(), T_B_S, p_D_L, 1.5)));
    std::unique_ptr<ceres::CostFunction> automatic(StereoPointFactor::CreateAutoDiff(
        std::make_unique<StereoPointFactor>(p_S, StereoCovariance(), T_B_S, p_D_L, 1.5)));
    const Vector7 x = ToBlock(T_D_B);
    test::ExpectSameTangentJacobian<3>(*analytic, *automatic, x.data());
  }
}

// A measurement offset by -d in S gives e = d and r = sqrt(w) sqrt_info d.
TEST(StereoPointFactorTest, KnownPointOffsetGivesSqrtInfoTimesOffset) {
  const Pose3 T_B_S = ForwardDownExtrinsic();
  const Pose3 T_D_B = TestPoses()[3];
  const Eigen::Vector3d p_S_true(0.1, 0.2, 4.0);
  const Eigen::Vector3d p_D_L = T_D_B * (T_B_S * p_S_true);
  const Eigen::Vector3d d(0.03, -0.02, 0.15);
  const Eigen::Matrix3d covariance = StereoCovariance();
  const double w = 0.25;
  const StereoPointFactor factor(p_S_true - d, covariance, T_B_S, p_D_L, w);
  const Vector7 x = ToBlock(T_D_B);

  EXPECT_NEAR((factor.UnweightedError(x.data()) - d).norm(), 0.0, 1e-12);
  double r[3];
  ASSERT_TRUE(factor(x.data(), r));
  const Eigen::Vector3d expected = std::sqrt(w) * factor.sqrt_information() * d;
  EXPECT_NEAR((Eigen::Vector3d(r[0], r[1], r[2]) - expected).norm(), 0.0, 1e-9);
  const Eigen::Matrix3d S = factor.sqrt_information();
  EXPECT_NEAR((S.transpose() * S - covariance.inverse()).norm() / covariance.inverse().norm(), 0.0,
              1e-12);
  // Gating ignores the stage weight.
  EXPECT_NEAR(factor.SquaredMahalanobis(x.data()), d.dot(covariance.inverse() * d), 1e-8);
}

// Depth is the weak direction: an error of one depth sigma along z_S costs 1, the same metres
// across the ray cost (0.08 / 0.01)^2 = 64.
TEST(StereoPointFactorTest, DepthIsTheWeakDirectionOfTheCovariance) {
  const Pose3 T_B_S = ForwardDownExtrinsic();
  const Pose3 T_D_B = TestPoses()[2];
  const Eigen::Vector3d p_S(0.0, 0.0, 5.0);
  const Eigen::Vector3d p_D_L = T_D_B * (T_B_S * p_S);
  const Eigen::Matrix3d covariance = Eigen::Vector3d(1e-4, 1e-4, 6.4e-3).asDiagonal();
  const Vector7 x = ToBlock(T_D_B);
  const StereoPointFactor along(p_S - Eigen::Vector3d(0, 0, 0.08), covariance, T_B_S, p_D_L);
  const StereoPointFactor across(p_S - Eigen::Vector3d(0.08, 0, 0), covariance, T_B_S, p_D_L);
  EXPECT_NEAR(along.SquaredMahalanobis(x.data()), 1.0, 1e-9);
  EXPECT_NEAR(across.SquaredMahalanobis(x.data()), 64.0, 1e-7);
}

// Level body, S with the body's axes: moving the body by +dx along D's x axis moves the light by
// -dx in S.
TEST(StereoPointFactorTest, PureBodyTranslationMovesThePredictionTheOtherWay) {
  const Pose3 T_B_S(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.5, 0.0, 0.0));
  const Eigen::Vector3d p_D_L(3.0, 0.2, 0.1);
  const double at_rest[7] = {0, 0, 0, 0, 0, 0, 1};
  const StereoPointFactor factor(Eigen::Vector3d(2.5, 0.2, 0.1), Eigen::Matrix3d::Identity(), T_B_S,
                                 p_D_L);
  EXPECT_NEAR(factor.UnweightedError(at_rest).norm(), 0.0, 1e-15);
  const double moved[7] = {0.3, 0, 0, 0, 0, 0, 1};
  EXPECT_NEAR((factor.UnweightedError(moved) - Eigen::Vector3d(-0.3, 0, 0)).norm(), 0.0, 1e-15);
}

TEST(StereoPointFactorTest, RejectsInvalidConstruction) {
  const Pose3 T_B_S = ForwardDownExtrinsic();
  const Eigen::Vector3d p(0, 0, 2);
  Eigen::Matrix3d singular = Eigen::Matrix3d::Identity();
  singular(2, 2) = 0.0;
  Eigen::Matrix3d asymmetric = Eigen::Matrix3d::Identity();
  asymmetric(0, 1) = 0.3;
  EXPECT_THROW(StereoPointFactor(p, singular, T_B_S, p), std::invalid_argument);
  EXPECT_THROW(StereoPointFactor(p, asymmetric, T_B_S, p), std::invalid_argument);
  EXPECT_THROW(StereoPointFactor(p, Eigen::Matrix3d::Identity(), T_B_S, p, -1.0),
               std::invalid_argument);
  EXPECT_THROW(
      StereoPointFactor(Eigen::Vector3d(0, std::nan(""), 1), Eigen::Matrix3d::Identity(), T_B_S, p),
      std::invalid_argument);
}

// Three non-collinear noise-free lights and a perturbed start: the pose is recovered.
TEST(StereoPointFactorTest, PerturbedPoseIsRecoveredFromPerfectPoints) {
  const Pose3 T_B_S = ForwardDownExtrinsic();
  const Pose3 T_D_B_true(Eigen::Quaterniond(Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitZ())),
                         Eigen::Vector3d(-3.0, 0.5, -1.5));
  const std::vector<Eigen::Vector3d> lights = {{0.0, 0.0, 0.0}, {0.8, 0.0, 0.0}, {0.0, 0.6, 0.0}};
  Vector7 x = ToBlock(
      Pose3(Eigen::Quaterniond(Eigen::AngleAxisd(-0.3, Eigen::Vector3d(0.1, -0.2, 1).normalized())),
            Eigen::Vector3d(-2.7, 0.7, -1.8)));
  ceres::Problem problem;
  for (const Eigen::Vector3d& p_D_L : lights) {
    const Eigen::Vector3d p_S = (T_D_B_true * T_B_S).Inverse() * p_D_L;
    problem.AddResidualBlock(StereoPointFactor::Create(p_S, StereoCovariance(), T_B_S, p_D_L),
                             nullptr, x.data());
  }
  problem.SetManifold(x.data(), new PoseManifold);
  ceres::Solver::Options options;
  options.max_num_iterations = 100;
  options.function_tolerance = 1e-16;
  options.gradient_tolerance = 1e-16;
  options.parameter_tolerance = 1e-14;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  const Pose3 T = FromBlock(x);
  EXPECT_NEAR((T.p - T_D_B_true.p).norm(), 0.0, 1e-7);
  EXPECT_NEAR(RotationAngleBetween(T.q, T_D_B_true.q), 0.0, 1e-7);
}

}  // namespace
}  // namespace auvdock
