#include "factors/mono_reprojection_factor.h"

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include "auvdock/camera/pinhole_radtan_camera.h"
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

Eigen::Quaterniond SmallRotation(std::mt19937_64& rng, double sigma) {
  std::normal_distribution<double> n(0.0, sigma);
  return QuaternionExp<double>(Eigen::Vector3d(n(rng), n(rng), n(rng)));
}

// A down-looking camera (image x = body y, image y = -body x, optical axis = body z, i.e. down),
// slightly tilted, with a lever arm.
Pose3 DownLookingExtrinsic(double tilt = 0.05) {
  Eigen::Matrix3d R_B_C;
  R_B_C << 0, -1, 0,  //
      1, 0, 0,        //
      0, 0, 1;
  const Eigen::Quaterniond tilt_q(Eigen::AngleAxisd(tilt, Eigen::Vector3d(1, 2, 0).normalized()));
  return Pose3(tilt_q * Eigen::Quaterniond(R_B_C), Eigen::Vector3d(0.3, -0.05, 0.12));
}

PinholeRadtanCamera DistortedCamera() {
  return PinholeRadtanCamera(1280, 1024, 820.0, 815.0, 641.5, 509.0,
                             {-0.28, 0.09, 1.2e-3, -7e-4, -0.012});
}

PinholeRadtanCamera PinholeCamera() {
  return PinholeRadtanCamera(1280, 1024, 800.0, 800.0, 640.0, 512.0, {0, 0, 0, 0, 0});
}

// The light that the camera sees at p_C when the body is at T_D_B.
Eigen::Vector3d LightAt(const Pose3& T_D_B, const Pose3& T_B_C, const Eigen::Vector3d& p_C) {
  return T_D_B * (T_B_C * p_C);
}

// Reference projection through Pose3 and PinholeRadtanCamera::Project.
Eigen::Vector2d ReferencePixel(const PinholeRadtanCamera& camera, const Pose3& T_D_B,
                               const Pose3& T_B_C, const Eigen::Vector3d& p_D_L) {
  const std::optional<Eigen::Vector2d> uv = camera.Project((T_D_B * T_B_C).Inverse() * p_D_L);
  EXPECT_TRUE(uv.has_value());
  return uv.value_or(Eigen::Vector2d::Zero());
}

// Ridders' default first step (1 % of each ambient coordinate, i.e. a centimetre-scale move of
// a light 2 m away) is too coarse for the perspective division and its extrapolation stalls at
// ~1e-3 relative error; 0.1 % lets it converge to ~1e-12 (checked against central differences
// through PoseManifold::Plus).
ceres::NumericDiffOptions CheckerOptions() {
  ceres::NumericDiffOptions options;
  options.ridders_relative_initial_step_size = 1e-3;
  return options;
}

// Identity, near-identity and random body poses.
std::vector<Pose3> TestPoses() {
  std::mt19937_64 rng(11);
  std::vector<Pose3> poses = {Pose3::Identity(),
                              Pose3(SmallRotation(rng, 1e-3), Eigen::Vector3d(1e-3, -2e-3, 5e-4))};
  std::normal_distribution<double> n(0.0, 2.0);
  for (int i = 0; i < 4; ++i) {
    poses.emplace_back(RandomRotation(rng), Eigen::Vector3d(n(rng), n(rng), n(rng)));
  }
  return poses;
}

TEST(MonoReprojectionFactorTest, PerfectMeasurementGivesZeroResidual) {
  const PinholeRadtanCamera camera = DistortedCamera();
  const Pose3 T_B_C = DownLookingExtrinsic();
  for (const Pose3& T_D_B : TestPoses()) {
    const Eigen::Vector3d p_D_L = LightAt(T_D_B, T_B_C, Eigen::Vector3d(-0.4, 0.3, 2.5));
    const Eigen::Vector2d uv = ReferencePixel(camera, T_D_B, T_B_C, p_D_L);
    const MonoReprojectionFactor factor(uv, 0.09 * Eigen::Matrix2d::Identity(), camera, T_B_C,
                                        p_D_L);
    const Vector7 x = ToBlock(T_D_B);
    double r[2];
    ASSERT_TRUE(factor(x.data(), r));
    EXPECT_NEAR(r[0], 0.0, 1e-8);
    EXPECT_NEAR(r[1], 0.0, 1e-8);
    EXPECT_NEAR(factor.SquaredMahalanobis(x.data()), 0.0, 1e-14);
  }
}

TEST(MonoReprojectionFactorTest, JacobiansPassTheGradientCheckerWithThePoseManifold) {
  const PinholeRadtanCamera camera = DistortedCamera();
  const Pose3 T_B_C = DownLookingExtrinsic();
  const PoseManifold manifold;
  std::vector<const ceres::Manifold*> manifolds = {&manifold};
  Eigen::Matrix2d covariance;
  covariance << 0.16, 0.03, 0.03, 0.25;
  for (const Pose3& T_D_B : TestPoses()) {
    // Off-centre light and a measurement 3 px away, so the residual is not zero.
    const Eigen::Vector3d p_D_L = LightAt(T_D_B, T_B_C, Eigen::Vector3d(0.7, -0.5, 1.8));
    const Eigen::Vector2d uv =
        ReferencePixel(camera, T_D_B, T_B_C, p_D_L) + Eigen::Vector2d(2.0, -2.2);
    std::unique_ptr<ceres::CostFunction> cost(
        MonoReprojectionFactor::Create(uv, covariance, camera, T_B_C, p_D_L, 0.7));
    const Vector7 x = ToBlock(T_D_B);
    const double* params[1] = {x.data()};
    ceres::GradientChecker checker(cost.get(), &manifolds, CheckerOptions());
    ceres::GradientChecker::ProbeResults results;
    EXPECT_TRUE(checker.Probe(params, 1e-7, &results)) << results.error_log;
  }
}

// The analytic Jacobian (Create) against ceres::Jet's (CreateAutoDiff) in the tangent space
// (ambient Jacobian times the manifold's PlusJacobian), with a strongly distorted camera and a
// full covariance; and the residuals equal.
TEST(MonoReprojectionFactorTest, AnalyticJacobianEqualsAutomaticDifferentiation) {
  const PinholeRadtanCamera camera = DistortedCamera();
  const Pose3 T_B_C = DownLookingExtrinsic();
  Eigen::Matrix2d covariance;
  covariance << 0.16, 0.03, 0.03, 0.25;
  for (const Pose3& T_D_B : TestPoses()) {
    for (const Eigen::Vector3d& in_camera :
         {Eigen::Vector3d(0.7, -0.5, 1.8), Eigen::Vector3d(-1.2, 0.9, 2.0),
          Eigen::Vector3d(0.0, 0.0, 4.0)}) {
      const Eigen::Vector3d p_D_L = LightAt(T_D_B, T_B_C, in_camera);
      const Eigen::Vector2d uv =
          ReferencePixel(camera, T_D_B, T_B_C, p_D_L) + Eigen::Vector2d(2.0, -2.2);
      std::unique_ptr<ceres::CostFunction> analytic(MonoReprojectionFactor::Create(
          std::make_unique<MonoReprojectionFactor>(uv, covariance, camera, T_B_C, p_D_L, 0.7)));
      std::unique_ptr<ceres::CostFunction> automatic(MonoReprojectionFactor::CreateAutoDiff(
          std::make_unique<MonoReprojectionFactor>(uv, covariance, camera, T_B_C, p_D_L, 0.7)));
      const Vector7 x = ToBlock(T_D_B);
      test::ExpectSameTangentJacobian<2>(*analytic, *automatic, x.data());
    }
  }
}

// The Jacobian in the pose's tangent space (tangent_jacobians.h, for the chain solver) is the
// ambient one times the PlusJacobian, and the residual the same.
TEST(MonoReprojectionFactorTest, TangentSpaceJacobianIsTheAmbientOneProjected) {
  const PinholeRadtanCamera camera = DistortedCamera();
  const Pose3 T_B_C = DownLookingExtrinsic();
  for (const Pose3& T_D_B : TestPoses()) {
    const Eigen::Vector3d p_D_L = LightAt(T_D_B, T_B_C, Eigen::Vector3d(0.7, -0.5, 1.8));
    const Eigen::Vector2d uv =
        ReferencePixel(camera, T_D_B, T_B_C, p_D_L) + Eigen::Vector2d(1.5, -0.8);
    std::unique_ptr<ceres::CostFunction> factor(MonoReprojectionFactor::Create(
        std::make_unique<MonoReprojectionFactor>(uv, 0.09 * Eigen::Matrix2d::Identity(), camera,
                                                 T_B_C, p_D_L, 0.7)));
    const auto* in_tangent = dynamic_cast<const TangentJacobians*>(factor.get());
    ASSERT_NE(in_tangent, nullptr);
    const Vector7 x = ToBlock(T_D_B);
    const double* parameters[] = {x.data()};
    Eigen::Matrix<double, 2, kPoseSize, Eigen::RowMajor> A;
    Eigen::Matrix<double, 2, kPoseTangentSize, Eigen::RowMajor> T;
    double* a[] = {A.data()};
    double* t[] = {T.data()};
    Eigen::Vector2d r_ambient, r_tangent;
    ASSERT_TRUE(factor->Evaluate(parameters, r_ambient.data(), a));
    ASSERT_TRUE(in_tangent->EvaluateInTangentSpace(parameters, r_tangent.data(), t));
    EXPECT_EQ(r_ambient, r_tangent);
    Eigen::Matrix<double, kPoseSize, kPoseTangentSize, Eigen::RowMajor> plus;
    PoseManifold().PlusJacobian(x.data(), plus.data());
    EXPECT_LT((A * plus - T).cwiseAbs().maxCoeff(), 1e-10 * (1.0 + T.cwiseAbs().maxCoeff()));
  }
}

// Undistorted pinhole, down-looking camera at the body origin, level body 2 m above a light
// right below it. Moving the body by dx along the dock's x axis moves the light by -dx in B, i.e.
// +dx along the image's y axis (image y = -body x): the pixel moves by fy dx / Z in v.
TEST(MonoReprojectionFactorTest, PureXOffsetGivesTheExpectedPixelShift) {
  const PinholeRadtanCamera camera = PinholeCamera();
  const Pose3 T_B_C(DownLookingExtrinsic(0.0).q, Eigen::Vector3d::Zero());
  const Eigen::Vector3d p_D_L = Eigen::Vector3d::Zero();
  const double sigma = 0.5;
  const Eigen::Vector2d uv_centre(640.0, 512.0);
  const MonoReprojectionFactor factor(uv_centre, sigma * sigma * Eigen::Matrix2d::Identity(),
                                      camera, T_B_C, p_D_L);
  const MonoReprojectionFactor weighted(uv_centre, sigma * sigma * Eigen::Matrix2d::Identity(),
                                        camera, T_B_C, p_D_L, 4.0);

  const double dx = 0.1;
  const double at_rest[7] = {0.0, 0.0, -2.0, 0, 0, 0, 1};
  const double moved[7] = {dx, 0.0, -2.0, 0, 0, 0, 1};
  Eigen::Vector2d e;
  ASSERT_TRUE(factor.UnweightedError(at_rest, &e));
  EXPECT_NEAR(e.norm(), 0.0, 1e-12);
  ASSERT_TRUE(factor.UnweightedError(moved, &e));
  EXPECT_NEAR(e.x(), 0.0, 1e-12);
  EXPECT_NEAR(e.y(), 800.0 * dx / 2.0, 1e-9);  // 40 px

  double r[2];
  ASSERT_TRUE(factor(moved, r));
  EXPECT_NEAR(r[0], 0.0, 1e-12);
  EXPECT_NEAR(r[1], 40.0 / sigma, 1e-9);
  EXPECT_NEAR(factor.SquaredMahalanobis(moved), (40.0 / sigma) * (40.0 / sigma), 1e-6);
  // The information weight scales the residual by sqrt(w) but not the gating distance.
  ASSERT_TRUE(weighted(moved, r));
  EXPECT_NEAR(r[1], 2.0 * 40.0 / sigma, 1e-9);
  EXPECT_NEAR(weighted.SquaredMahalanobis(moved), factor.SquaredMahalanobis(moved), 1e-9);
  EXPECT_NEAR(factor.DepthInCamera(moved), 2.0, 1e-12);
}

TEST(MonoReprojectionFactorTest, AgreesWithPinholeRadtanCameraProjectForDistortedCameras) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::vector<PinholeRadtanCamera> cameras = {
      DistortedCamera(),
      PinholeRadtanCamera(1280, 1024, 700.0, 700.0, 630.0, 520.0, {0.12, -0.03, 0, 0, 0}),
      PinholeRadtanCamera(800, 600, 500.0, 505.0, 401.0, 299.0, {-0.1, 0.01, -2e-3, 1.5e-3, 0})};
  for (const PinholeRadtanCamera& camera : cameras) {
    for (int trial = 0; trial < 20; ++trial) {
      const Pose3 T_D_B(RandomRotation(rng), 3.0 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
      const Pose3 T_B_C(RandomRotation(rng), 0.3 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
      const double z = 1.0 + 4.0 * (u(rng) + 1.0);
      const Eigen::Vector3d p_C(0.5 * z * u(rng), 0.4 * z * u(rng), z);
      const Eigen::Vector3d p_D_L = LightAt(T_D_B, T_B_C, p_C);
      const Eigen::Vector2d uv_measured(100.0, 200.0);
      const MonoReprojectionFactor factor(uv_measured, Eigen::Matrix2d::Identity(), camera, T_B_C,
                                          p_D_L);
      const Vector7 x = ToBlock(T_D_B);
      Eigen::Vector2d e;
      ASSERT_TRUE(factor.UnweightedError(x.data(), &e));
      const Eigen::Vector2d expected = camera.Project(p_C).value();
      EXPECT_NEAR((e + uv_measured - expected).norm(), 0.0, 1e-8) << trial;
      EXPECT_NEAR((factor.PointInCamera(x.data()) - p_C).norm(), 0.0, 1e-10);
    }
  }
}

// Behind the camera (Z <= kMinDepth) the residual is not evaluated: operator() and Evaluate
// return false (Ceres rejects such a step), the unweighted error reports false, and the gating
// distance is +infinity so a gate always rejects the light.
TEST(MonoReprojectionFactorTest, LightBehindTheCameraIsReportedAsInfeasible) {
  const PinholeRadtanCamera camera = DistortedCamera();
  const Pose3 T_B_C = DownLookingExtrinsic();
  const Pose3 T_D_B = TestPoses()[3];
  for (const double z : {-2.0, 0.0, 0.5 * MonoReprojectionFactor::kMinDepth}) {
    const Eigen::Vector3d p_D_L = LightAt(T_D_B, T_B_C, Eigen::Vector3d(0.1, 0.2, z));
    std::unique_ptr<ceres::CostFunction> cost(MonoReprojectionFactor::Create(
        Eigen::Vector2d(640, 512), Eigen::Matrix2d::Identity(), camera, T_B_C, p_D_L));
    const MonoReprojectionFactor factor(Eigen::Vector2d(640, 512), Eigen::Matrix2d::Identity(),
                                        camera, T_B_C, p_D_L);
    const Vector7 x = ToBlock(T_D_B);
    const double* params[1] = {x.data()};
    double r[2];
    double J[14];
    double* jacobians[1] = {J};
    EXPECT_FALSE(cost->Evaluate(params, r, nullptr)) << z;
    EXPECT_FALSE(cost->Evaluate(params, r, jacobians)) << z;
    Eigen::Vector2d e;
    EXPECT_FALSE(factor.UnweightedError(x.data(), &e));
    EXPECT_EQ(factor.SquaredMahalanobis(x.data()), std::numeric_limits<double>::infinity());
    EXPECT_NEAR(factor.DepthInCamera(x.data()), z, 1e-9);
  }
}

TEST(MonoReprojectionFactorTest, SquaredMahalanobisUsesTheFullCovariance) {
  const PinholeRadtanCamera camera = DistortedCamera();
  const Pose3 T_B_C = DownLookingExtrinsic();
  const Pose3 T_D_B = TestPoses()[2];
  const Eigen::Vector3d p_D_L = LightAt(T_D_B, T_B_C, Eigen::Vector3d(0.2, 0.1, 3.0));
  const Eigen::Vector2d offset(1.5, -0.7);
  const Eigen::Vector2d uv = ReferencePixel(camera, T_D_B, T_B_C, p_D_L) - offset;
  Eigen::Matrix2d covariance;
  covariance << 0.3, -0.1, -0.1, 0.2;
  const MonoReprojectionFactor factor(uv, covariance, camera, T_B_C, p_D_L);
  const Vector7 x = ToBlock(T_D_B);
  Eigen::Vector2d e;
  ASSERT_TRUE(factor.UnweightedError(x.data(), &e));
  EXPECT_NEAR((e - offset).norm(), 0.0, 1e-8);
  EXPECT_NEAR(factor.SquaredMahalanobis(x.data()), offset.dot(covariance.inverse() * offset), 1e-8);
  const Eigen::Matrix2d S = factor.sqrt_information();
  EXPECT_NEAR((S.transpose() * S - covariance.inverse()).norm(), 0.0, 1e-12);
}

TEST(MonoReprojectionFactorTest, RejectsInvalidConstruction) {
  const PinholeRadtanCamera camera = DistortedCamera();
  const Pose3 T_B_C = DownLookingExtrinsic();
  const Eigen::Vector2d uv(640, 512);
  const Eigen::Vector3d p(0, 0, 2);
  const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
  Eigen::Matrix2d not_pd;
  not_pd << 1.0, 2.0, 2.0, 1.0;
  Eigen::Matrix2d asymmetric;
  asymmetric << 1.0, 0.5, 0.0, 1.0;
  EXPECT_THROW(MonoReprojectionFactor(uv, not_pd, camera, T_B_C, p), std::invalid_argument);
  EXPECT_THROW(MonoReprojectionFactor(uv, asymmetric, camera, T_B_C, p), std::invalid_argument);
  EXPECT_THROW(MonoReprojectionFactor(uv, Eigen::Matrix2d::Zero(), camera, T_B_C, p),
               std::invalid_argument);
  EXPECT_THROW(MonoReprojectionFactor(uv, I, camera, T_B_C, p, 0.0), std::invalid_argument);
  EXPECT_THROW(MonoReprojectionFactor(Eigen::Vector2d(std::nan(""), 0.0), I, camera, T_B_C, p),
               std::invalid_argument);
  EXPECT_THROW(MonoReprojectionFactor(uv, I, PinholeRadtanCamera(), T_B_C, p),
               std::invalid_argument);
}

// Five noise-free lights on the dock, a perturbed start: the pose is recovered.
TEST(MonoReprojectionFactorTest, PerturbedPoseIsRecoveredFromPerfectPixels) {
  const PinholeRadtanCamera camera = DistortedCamera();
  const Pose3 T_B_C = DownLookingExtrinsic();
  const Pose3 T_D_B_true(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())),
                         Eigen::Vector3d(0.4, -0.2, -2.5));
  const std::vector<Eigen::Vector3d> lights = {
      {0.0, 0.0, 0.0}, {0.8, 0.0, 0.0}, {-0.8, 0.0, 0.0}, {0.0, 0.6, 0.0}, {0.3, -0.5, 0.05}};
  Vector7 x = ToBlock(
      Pose3(Eigen::Quaterniond(Eigen::AngleAxisd(0.38, Eigen::Vector3d(0.2, 0.3, 1).normalized())),
            Eigen::Vector3d(0.5, -0.1, -2.3)));
  ceres::Problem problem;
  for (const Eigen::Vector3d& p_D_L : lights) {
    const Eigen::Vector2d uv = ReferencePixel(camera, T_D_B_true, T_B_C, p_D_L);
    problem.AddResidualBlock(MonoReprojectionFactor::Create(uv, 0.09 * Eigen::Matrix2d::Identity(),
                                                            camera, T_B_C, p_D_L),
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
