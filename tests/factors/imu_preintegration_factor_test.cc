#include "factors/imu_preintegration_factor.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include "auvdock/geometry/dock_model.h"
#include "factors/pose_manifold.h"

namespace auvdock {
namespace {

const Eigen::Vector3d kGravity_D(0.0, 0.0, 9.81);

// One estimator state in the factor's block layout.
struct State {
  double pose[kPoseSize] = {0, 0, 0, 0, 0, 0, 1};
  double velocity[kVelocitySize] = {0, 0, 0};
  double bias[kBiasSize] = {0, 0, 0, 0, 0, 0};

  Eigen::Map<Eigen::Vector3d> p() { return Eigen::Map<Eigen::Vector3d>(pose); }
  Eigen::Map<Eigen::Quaterniond> q() { return Eigen::Map<Eigen::Quaterniond>(pose + 3); }
  Eigen::Map<Eigen::Vector3d> v() { return Eigen::Map<Eigen::Vector3d>(velocity); }
  ImuBias imu_bias() const {
    ImuBias b;
    b.gyro = Eigen::Vector3d(bias[0], bias[1], bias[2]);
    b.accel = Eigen::Vector3d(bias[3], bias[4], bias[5]);
    return b;
  }
  NavState nav() {
    NavState s;
    s.q_D_B = q();
    s.p_D = p();
    s.v_D = v();
    return s;
  }
  void set_nav(const NavState& s) {
    q() = s.q_D_B;
    p() = s.p_D;
    v() = s.v_D;
  }
};

// 0.5 s of a turning, accelerating vehicle at 200 Hz about a non-zero linearisation bias.
ImuPreintegration MakePreintegration(std::mt19937_64& rng) {
  ImuBias bias_hat;
  bias_hat.gyro = Eigen::Vector3d(0.003, -0.002, 0.001);
  bias_hat.accel = Eigen::Vector3d(0.05, 0.02, -0.04);
  ImuPreintegration pim(ImuNoiseDensities{}, bias_hat);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  for (int k = 0; k < 100; ++k) {
    const double t = 0.005 * k;
    Eigen::Vector3d gyro(0.2 * std::sin(t), -0.3, 0.4 * t);
    Eigen::Vector3d accel(0.5, 0.3 * std::cos(2 * t), -9.7);
    // One draw per statement so that the seeded sequence does not depend on the compiler's
    // argument evaluation order.
    for (int c = 0; c < 3; ++c) gyro[c] += jitter(rng);
    for (int c = 0; c < 3; ++c) accel[c] += jitter(rng);
    pim.Integrate(gyro, accel, 0.005);
  }
  return pim;
}

Eigen::Quaterniond RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Quaterniond q;
  for (int c = 0; c < 4; ++c) q.coeffs()[c] = normal(rng);
  return q.normalized();
}

Eigen::Vector3d RandomVector(std::mt19937_64& rng, double sigma) {
  std::normal_distribution<double> normal(0.0, sigma);
  Eigen::Vector3d v;
  for (int c = 0; c < 3; ++c) v[c] = normal(rng);
  return v;
}

// State j exactly as the preintegration predicts it from state i and bias_i (the factor's own
// measurement model), with bias_j = bias_i.
State PredictedStateJ(const ImuPreintegration& pim, State state_i) {
  State state_j;
  state_j.set_nav(pim.Predict(state_i.nav(), state_i.imu_bias(), kGravity_D));
  std::copy(state_i.bias, state_i.bias + kBiasSize, state_j.bias);
  return state_j;
}

State RandomStateI(std::mt19937_64& rng) {
  State s;
  s.p() = RandomVector(rng, 5.0);
  s.q() = RandomRotation(rng);
  s.v() = RandomVector(rng, 1.0);
  // A bias away from the linearisation point, so the first-order correction is in play.
  const Eigen::Vector3d bg = RandomVector(rng, 0.01), ba = RandomVector(rng, 0.1);
  std::copy(bg.data(), bg.data() + 3, s.bias);
  std::copy(ba.data(), ba.data() + 3, s.bias + 3);
  return s;
}

Eigen::Matrix<double, 15, 1> Residual(const ceres::CostFunction& cost, const State& i,
                                      const State& j) {
  const double* parameters[] = {i.pose, i.velocity, i.bias, j.pose, j.velocity, j.bias};
  Eigen::Matrix<double, 15, 1> r;
  EXPECT_TRUE(cost.Evaluate(parameters, r.data(), nullptr));
  return r;
}

TEST(ImuPreintegrationFactor, PerfectDataGivesZeroResidual) {
  std::mt19937_64 rng(1);
  const ImuPreintegration pim = MakePreintegration(rng);
  const std::unique_ptr<ceres::CostFunction> cost(ImuPreintegrationFactor::Create(pim, kGravity_D));
  for (int trial = 0; trial < 10; ++trial) {
    State i = RandomStateI(rng);
    State j = PredictedStateJ(pim, i);
    EXPECT_LT(Residual(*cost, i, j).norm(), 1e-7) << trial;
    const ImuPreintegrationFactor factor(pim, kGravity_D);
    EXPECT_LT(factor.UnweightedError(i.pose, i.velocity, i.bias, j.pose, j.velocity, j.bias).norm(),
              1e-12)
        << trial;
  }
}

// The residual's Jacobians, analytic (production) and autodiff (reference), against numeric
// differentiation through the production manifolds: PoseManifold for both poses, Euclidean for
// velocities and biases.
class ImuFactorJacobians : public ::testing::TestWithParam<bool> {};

TEST_P(ImuFactorJacobians, GradientCheckerPassesAtIdentityNearIdentityAndRandomPoints) {
  const bool analytic = GetParam();
  std::mt19937_64 rng(2);
  const ImuPreintegration pim = MakePreintegration(rng);
  const std::unique_ptr<ceres::CostFunction> cost(
      analytic ? ImuPreintegrationFactor::Create(pim, kGravity_D)
               : ImuPreintegrationFactor::CreateAutoDiff(pim, kGravity_D));
  const PoseManifold pose_manifold;
  const std::vector<const ceres::Manifold*> manifolds = {&pose_manifold, nullptr, nullptr,
                                                         &pose_manifold, nullptr, nullptr};
  ceres::NumericDiffOptions options;
  const ceres::GradientChecker checker(cost.get(), &manifolds, options);

  enum class Point { kIdentity, kNearIdentity, kRandom };
  double worst_relative_error = 0.0;
  for (const Point point :
       {Point::kIdentity, Point::kNearIdentity, Point::kRandom, Point::kRandom, Point::kRandom}) {
    State i, j;  // identity poses, zero velocities and biases
    if (point == Point::kNearIdentity) {
      for (State* s : {&i, &j}) {
        s->p() = RandomVector(rng, 1e-3);
        s->q() = QuaternionExp<double>(RandomVector(rng, 1e-3));
        s->v() = RandomVector(rng, 1e-3);
        for (double& b : s->bias) b = 1e-4 * std::normal_distribution<double>()(rng);
      }
    } else if (point == Point::kRandom) {
      // A random state i and a state j near its prediction (0.2 rad, 0.3 m, 0.1 m/s off) so the
      // rotation error stays far from the Log's cut at pi.
      i = RandomStateI(rng);
      j = PredictedStateJ(pim, i);
      j.p() += RandomVector(rng, 0.3);
      j.q() = (QuaternionExp<double>(RandomVector(rng, 0.2)) * j.q()).normalized();
      j.v() += RandomVector(rng, 0.1);
      for (double& b : j.bias) b += 0.01 * std::normal_distribution<double>()(rng);
    }
    const double* parameters[] = {i.pose, i.velocity, i.bias, j.pose, j.velocity, j.bias};
    ceres::GradientChecker::ProbeResults results;
    EXPECT_TRUE(checker.Probe(parameters, 1e-6, &results))
        << "point " << static_cast<int>(point) << ": " << results.error_log;
    worst_relative_error = std::max(worst_relative_error, results.maximum_relative_error);
  }
  RecordProperty("worst_relative_error", ::testing::PrintToString(worst_relative_error));
}

INSTANTIATE_TEST_SUITE_P(AnalyticAndAutoDiff, ImuFactorJacobians, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return info.param ? std::string("Analytic") : std::string("AutoDiff");
                         });

// The analytic residual and ambient Jacobians equal the autodiff ones to rounding, at random
// states with biases away from the linearisation point and rotation errors up to ~0.5 rad.
TEST(ImuPreintegrationFactor, AnalyticJacobiansEqualAutoDiff) {
  std::mt19937_64 rng(12);
  const ImuPreintegration pim = MakePreintegration(rng);
  const std::unique_ptr<ceres::CostFunction> analytic(
      ImuPreintegrationFactor::Create(pim, kGravity_D));
  const std::unique_ptr<ceres::CostFunction> autodiff(
      ImuPreintegrationFactor::CreateAutoDiff(pim, kGravity_D));
  const int sizes[] = {kPoseSize, kVelocitySize, kBiasSize, kPoseSize, kVelocitySize, kBiasSize};
  for (int trial = 0; trial < 20; ++trial) {
    State i = RandomStateI(rng);
    State j = PredictedStateJ(pim, i);
    j.p() += RandomVector(rng, 0.5);
    j.q() = (QuaternionExp<double>(RandomVector(rng, 0.3)) * j.q()).normalized();
    j.v() += RandomVector(rng, 0.2);
    for (double& b : j.bias) b += 0.01 * std::normal_distribution<double>()(rng);
    const double* parameters[] = {i.pose, i.velocity, i.bias, j.pose, j.velocity, j.bias};
    std::vector<std::vector<double>> J_analytic(6), J_autodiff(6);
    double* jacobians_analytic[6];
    double* jacobians_autodiff[6];
    for (int k = 0; k < 6; ++k) {
      J_analytic[k].assign(15 * sizes[k], 0.0);
      J_autodiff[k].assign(15 * sizes[k], 0.0);
      jacobians_analytic[k] = J_analytic[k].data();
      jacobians_autodiff[k] = J_autodiff[k].data();
    }
    Eigen::Matrix<double, 15, 1> r_analytic, r_autodiff;
    ASSERT_TRUE(analytic->Evaluate(parameters, r_analytic.data(), jacobians_analytic));
    ASSERT_TRUE(autodiff->Evaluate(parameters, r_autodiff.data(), jacobians_autodiff));
    EXPECT_LT((r_analytic - r_autodiff).norm(), 1e-9 * (1.0 + r_autodiff.norm())) << trial;
    // Compared in the tangent space: the autodiff residual uses q as stored, so its ambient
    // Jacobian has a component along q (the radial direction, never stepped along) that the
    // analytic one, written with q/|q|, does not.
    const PoseManifold pose_manifold;
    for (int k = 0; k < 6; ++k) {
      using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
      const Eigen::Map<const RowMajor> A(J_analytic[k].data(), 15, sizes[k]);
      const Eigen::Map<const RowMajor> B(J_autodiff[k].data(), 15, sizes[k]);
      Eigen::MatrixXd lift = Eigen::MatrixXd::Identity(sizes[k], sizes[k]);
      if (sizes[k] == kPoseSize) {
        Eigen::Matrix<double, kPoseSize, kPoseTangentSize, Eigen::RowMajor> plus;
        pose_manifold.PlusJacobian(parameters[k], plus.data());
        lift = plus;
      }
      const Eigen::MatrixXd A_tangent = A * lift, B_tangent = B * lift;
      EXPECT_LT((A_tangent - B_tangent).cwiseAbs().maxCoeff(),
                1e-7 * (1.0 + B_tangent.cwiseAbs().maxCoeff()))
          << "trial " << trial << ", block " << k;
    }
  }
}

// The Jacobians in the tangent spaces (tangent_jacobians.h, for the chain solver) are the ambient
// ones times each block's PlusJacobian, and the residuals the same.
TEST(ImuPreintegrationFactor, TangentSpaceJacobiansAreTheAmbientOnesProjected) {
  std::mt19937_64 rng(13);
  const ImuPreintegration pim = MakePreintegration(rng);
  const std::unique_ptr<ceres::CostFunction> factor(
      ImuPreintegrationFactor::Create(pim, kGravity_D));
  const auto* in_tangent = dynamic_cast<const TangentJacobians*>(factor.get());
  ASSERT_NE(in_tangent, nullptr);
  const int ambient[] = {kPoseSize, kVelocitySize, kBiasSize, kPoseSize, kVelocitySize, kBiasSize};
  const int tangent[] = {kPoseTangentSize, kVelocitySize, kBiasSize,
                         kPoseTangentSize, kVelocitySize, kBiasSize};
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  for (int trial = 0; trial < 10; ++trial) {
    State i = RandomStateI(rng);
    State j = PredictedStateJ(pim, i);
    j.p() += RandomVector(rng, 0.5);
    j.q() = (QuaternionExp<double>(RandomVector(rng, 0.3)) * j.q()).normalized();
    const double* parameters[] = {i.pose, i.velocity, i.bias, j.pose, j.velocity, j.bias};
    std::vector<RowMajor> A(6), T(6);
    double* a[6];
    double* t[6];
    for (int k = 0; k < 6; ++k) {
      A[k].resize(15, ambient[k]);
      T[k].resize(15, tangent[k]);
      a[k] = A[k].data();
      t[k] = T[k].data();
    }
    Eigen::Matrix<double, 15, 1> r_ambient, r_tangent;
    ASSERT_TRUE(factor->Evaluate(parameters, r_ambient.data(), a));
    ASSERT_TRUE(in_tangent->EvaluateInTangentSpace(parameters, r_tangent.data(), t));
    EXPECT_EQ(r_ambient, r_tangent);
    for (int k = 0; k < 6; ++k) {
      RowMajor projected = A[k];
      if (ambient[k] == kPoseSize) {
        Eigen::Matrix<double, kPoseSize, kPoseTangentSize, Eigen::RowMajor> plus;
        PoseManifold().PlusJacobian(parameters[k], plus.data());
        projected = A[k] * plus;
      }
      EXPECT_LT((projected - T[k]).cwiseAbs().maxCoeff(),
                1e-10 * (1.0 + T[k].cwiseAbs().maxCoeff()))
          << "trial " << trial << ", block " << k;
    }
  }
}

// Hand-worked offsets from the perfect state j: each one moves exactly its own error block, by
// the amount the formulas say, and the weighted residual is sqrt_info times that error.
TEST(ImuPreintegrationFactor, HandWorkedOffsetsGiveTheExpectedErrors) {
  std::mt19937_64 rng(3);
  const ImuPreintegration pim = MakePreintegration(rng);
  const ImuPreintegrationFactor factor(pim, kGravity_D);
  const std::unique_ptr<ceres::CostFunction> cost(ImuPreintegrationFactor::Create(pim, kGravity_D));
  State i = RandomStateI(rng);
  const Eigen::Matrix3d R_i = i.q().toRotationMatrix();
  const State perfect = PredictedStateJ(pim, i);

  auto error_of = [&](State j) {
    return factor.UnweightedError(i.pose, i.velocity, i.bias, j.pose, j.velocity, j.bias);
  };
  using Vector15 = ImuPreintegrationFactor::Vector15;

  // p_j off by a vector in D: e_p = R_i^T offset.
  const Eigen::Vector3d offset(0.3, -0.2, 0.1);
  State j = perfect;
  j.p() += offset;
  Vector15 expected = Vector15::Zero();
  expected.segment<3>(6) = R_i.transpose() * offset;
  EXPECT_LT((error_of(j) - expected).norm(), 1e-12);
  const Vector15 r = Residual(*cost, i, j);
  EXPECT_LT((r - factor.sqrt_information() * expected).norm(), 1e-9 * r.norm());
  // Consistent weighting: |r|^2 = e^T Sigma^-1 e.
  const double mahalanobis = expected.dot(factor.covariance().ldlt().solve(expected));
  EXPECT_NEAR(r.squaredNorm(), mahalanobis, 1e-9 * mahalanobis);
  EXPECT_NEAR(factor.SquaredMahalanobis(i.pose, i.velocity, i.bias, j.pose, j.velocity, j.bias),
              mahalanobis, 1e-9 * mahalanobis);

  // v_j off by dv: e_v = R_i^T dv, nothing else (e_p depends on v_i, not v_j).
  j = perfect;
  const Eigen::Vector3d dv(-0.05, 0.02, 0.04);
  j.v() += dv;
  expected.setZero();
  expected.segment<3>(3) = R_i.transpose() * dv;
  EXPECT_LT((error_of(j) - expected).norm(), 1e-12);

  // v_i off by dv (state j unchanged): e_v = -R_i^T dv and e_p = -R_i^T dv dt.
  State i_moved = i;
  i_moved.v() += dv;
  const Vector15 e_vi = factor.UnweightedError(i_moved.pose, i_moved.velocity, i_moved.bias,
                                               perfect.pose, perfect.velocity, perfect.bias);
  expected.setZero();
  expected.segment<3>(3) = -R_i.transpose() * dv;
  expected.segment<3>(6) = -R_i.transpose() * dv * pim.sum_dt();
  EXPECT_LT((e_vi - expected).norm(), 1e-12);

  // q_j turned by phi in its own body frame: e_theta = phi.
  j = perfect;
  const Eigen::Vector3d phi(0.01, -0.02, 0.03);
  j.q() = j.q() * QuaternionExp<double>(phi);
  expected.setZero();
  expected.segment<3>(0) = phi;
  EXPECT_LT((error_of(j) - expected).norm(), 1e-12);

  // Bias random walk: e_b = b_j - b_i, weighted by 1 / (sigma_bw sqrt(dt)).
  j = perfect;
  j.bias[1] += 1e-3;
  j.bias[5] -= 2e-2;
  expected.setZero();
  expected(10) = 1e-3;
  expected(14) = -2e-2;
  EXPECT_LT((error_of(j) - expected).norm(), 1e-12);
  const Vector15 r_bias = Residual(*cost, i, j);
  const ImuNoiseDensities& noise = pim.noise();
  EXPECT_NEAR(r_bias(10), 1e-3 / (noise.gyroscope_random_walk * std::sqrt(pim.sum_dt())), 1e-9);
  EXPECT_NEAR(r_bias(14), -2e-2 / (noise.accelerometer_random_walk * std::sqrt(pim.sum_dt())),
              1e-9);
}

TEST(ImuPreintegrationFactor, SqrtInformationWhitensTheCovariance) {
  std::mt19937_64 rng(4);
  const ImuPreintegrationFactor factor(MakePreintegration(rng), kGravity_D);
  const ImuPreintegrationFactor::Matrix15 whitened =
      factor.sqrt_information() * factor.covariance() * factor.sqrt_information().transpose();
  EXPECT_LT((whitened - ImuPreintegrationFactor::Matrix15::Identity()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_TRUE((factor.covariance().topLeftCorner<9, 9>().array() ==
               factor.preintegration().covariance().array())
                  .all());
}

// A small solve: state i held fixed, state j perturbed; the factor alone pulls it back to the
// prediction (through both pose manifolds).
TEST(ImuPreintegrationFactor, SolveRecoversThePredictedState) {
  std::mt19937_64 rng(5);
  const ImuPreintegration pim = MakePreintegration(rng);
  State i = RandomStateI(rng);
  const State perfect = PredictedStateJ(pim, i);
  State j = perfect;
  j.p() += RandomVector(rng, 0.5);
  j.q() = (QuaternionExp<double>(RandomVector(rng, 0.3)) * j.q()).normalized();
  j.v() += RandomVector(rng, 0.2);
  for (double& b : j.bias) b += 0.01;

  ceres::Problem problem;
  problem.AddResidualBlock(ImuPreintegrationFactor::Create(pim, kGravity_D), nullptr, i.pose,
                           i.velocity, i.bias, j.pose, j.velocity, j.bias);
  problem.SetManifold(i.pose, new PoseManifold);
  problem.SetManifold(j.pose, new PoseManifold);
  for (double* block : {i.pose, i.velocity, i.bias}) problem.SetParameterBlockConstant(block);
  ceres::Solver::Options options;
  options.max_num_iterations = 50;
  options.function_tolerance = 1e-16;
  options.gradient_tolerance = 1e-16;
  options.parameter_tolerance = 1e-14;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();

  State expected = perfect;
  EXPECT_LT((j.p() - expected.p()).norm(), 1e-8);
  EXPECT_LT(j.q().angularDistance(expected.q()), 1e-9);
  EXPECT_LT((j.v() - expected.v()).norm(), 1e-8);
  for (int k = 0; k < kBiasSize; ++k) EXPECT_NEAR(j.bias[k], perfect.bias[k], 1e-10);
}

// The Earth's rotation, exaggerated 300x so that its terms are far above the numeric
// differentiation's noise: the analytic Jacobians pass the gradient checker, equal the autodiff
// reference, and the state the preintegration predicts with the rate gives a zero residual.
TEST(ImuPreintegrationFactor, WithTheEarthsRotationJacobiansAndPredictionAgree) {
  std::mt19937_64 rng(21);
  const ImuPreintegration pim = MakePreintegration(rng);
  const Eigen::Vector3d w(0.02, -0.01, 0.03);
  const std::unique_ptr<ceres::CostFunction> analytic(
      ImuPreintegrationFactor::Create(pim, kGravity_D, w));
  const std::unique_ptr<ceres::CostFunction> autodiff(
      ImuPreintegrationFactor::CreateAutoDiff(pim, kGravity_D, w));
  const PoseManifold pose_manifold;
  const std::vector<const ceres::Manifold*> manifolds = {&pose_manifold, nullptr, nullptr,
                                                         &pose_manifold, nullptr, nullptr};
  const ceres::GradientChecker checker(analytic.get(), &manifolds, ceres::NumericDiffOptions());
  const ceres::GradientChecker reference(autodiff.get(), &manifolds, ceres::NumericDiffOptions());
  for (int trial = 0; trial < 5; ++trial) {
    State i = RandomStateI(rng);
    State j;
    j.set_nav(pim.Predict(i.nav(), i.imu_bias(), kGravity_D, w));
    std::copy(i.bias, i.bias + kBiasSize, j.bias);
    EXPECT_LT(Residual(*analytic, i, j).norm(), 1e-7) << trial;
    EXPECT_LT(Residual(*autodiff, i, j).norm(), 1e-7) << trial;
    j.p() += RandomVector(rng, 0.3);
    j.q() = (QuaternionExp<double>(RandomVector(rng, 0.2)) * j.q()).normalized();
    j.v() += RandomVector(rng, 0.1);
    const double* parameters[] = {i.pose, i.velocity, i.bias, j.pose, j.velocity, j.bias};
    ceres::GradientChecker::ProbeResults results, reference_results;
    EXPECT_TRUE(checker.Probe(parameters, 1e-6, &results)) << trial << ": " << results.error_log;
    EXPECT_TRUE(reference.Probe(parameters, 1e-6, &reference_results))
        << trial << ": " << reference_results.error_log;
    for (int k = 0; k < 6; ++k) {
      EXPECT_LT(
          (results.local_jacobians[k] - reference_results.local_jacobians[k]).cwiseAbs().maxCoeff(),
          1e-7 * (1.0 + reference_results.local_jacobians[k].cwiseAbs().maxCoeff()))
          << "trial " << trial << ", block " << k;
    }
  }
}

// Known answer: a navigation-grade IMU at 45 deg latitude, at rest in the Earth-fixed D and then
// cruising north at 2 m/s, for 1 s at 100 Hz. Its gyro measures the Earth's rate
// (R^T w_ie_D) and its accelerometer the Coriolis force's reaction (R^T (2 w x v - g)).
// With the Earth's rotation modelled the true states meet the factor: the rotation to rounding,
// the velocity and position to the preintegration's own first-order discretisation (the
// attitude held over each 10 ms step: g w dt / 2 per step, 4e-6 m/s over the second). Without
// it the rotation error is the Earth's turn over the second (7.29e-5 rad) and the velocity error
// the gravity turned by it (2.5e-4 m/s) less the Coriolis change (2.1e-4 m/s at 2 m/s north).
TEST(ImuPreintegrationFactor, TheEarthsRotationKnownAnswer) {
  DockModel dock;
  dock.latitude_rad = M_PI / 4.0;
  const Eigen::Vector3d w = EarthRate_D(dock);
  ASSERT_NEAR(w.norm(), kEarthRotationRate, 1e-15);
  EXPECT_NEAR(w.z(), -kEarthRotationRate * std::sqrt(0.5), 1e-15);  // up is -z
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
  for (const double speed : {0.0, 2.0}) {
    const Eigen::Vector3d v(speed, 0.0, 0.0);  // D's x is north at heading 0
    ImuPreintegration pim(ImuNoiseDensities{1e-5, 1e-7, 1e-3, 1e-5}, ImuBias());
    // D turns under the body: the body's attitude in D is held by a gyro that reads the Earth.
    const int n = 100;
    const double h = 0.01;
    for (int k = 0; k < n; ++k) {
      pim.Integrate(q.conjugate() * w, q.conjugate() * (2.0 * w.cross(v) - kGravity_D), h);
    }
    State i, j;
    i.q() = q;
    i.v() = v;
    j.q() = q;
    j.v() = v;
    j.p() = v * (n * h);
    const ImuPreintegrationFactor with(pim, kGravity_D, w), without(pim, kGravity_D);
    const auto e_with =
        with.UnweightedError(i.pose, i.velocity, i.bias, j.pose, j.velocity, j.bias);
    const auto e_without =
        without.UnweightedError(i.pose, i.velocity, i.bias, j.pose, j.velocity, j.bias);
    EXPECT_LT(e_with.head<3>().norm(), 1e-12) << speed;
    EXPECT_LT(e_with.segment<3>(3).norm(), 1e-5) << speed;
    EXPECT_LT(e_with.segment<3>(6).norm(), 1e-5) << speed;
    EXPECT_NEAR(e_without.head<3>().norm(), kEarthRotationRate * n * h, 1e-9) << speed;
    // Both along the same horizontal axis here (w x g and w x v are both along -y of D).
    const double turned_gravity = w.cross(kGravity_D).norm() * 0.5 * (n * h) * (n * h);
    const double coriolis = 2.0 * w.cross(v).norm() * (n * h);
    EXPECT_NEAR(e_without.segment<3>(3).norm(), std::abs(turned_gravity - coriolis), 1e-5) << speed;
  }
}

TEST(ImuPreintegrationFactor, RejectsAnEmptyOrSingularPreintegration) {
  const ImuPreintegration empty(ImuNoiseDensities{}, ImuBias{});
  EXPECT_THROW(ImuPreintegrationFactor(empty, kGravity_D), std::invalid_argument);

  ImuNoiseDensities silent;
  silent.gyroscope_noise_density = 0.0;
  silent.accelerometer_noise_density = 0.0;
  ImuPreintegration noiseless(silent, ImuBias{});
  noiseless.Integrate(Eigen::Vector3d::Zero(), -kGravity_D, 0.005);
  EXPECT_THROW(ImuPreintegrationFactor(noiseless, kGravity_D), std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
