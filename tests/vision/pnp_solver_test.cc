#include "auvdock/vision/pnp_solver.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <optional>
#include <random>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "auvdock/geometry/so3.h"
#include "auvdock/sim/docking_trajectory.h"
#include "auvdock/sim/scenario.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_scenarios.h"

namespace fs = std::filesystem;

namespace auvdock {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Problem {
  PinholeRadtanCamera camera;
  Pose3 T_C_D;
  std::vector<Eigen::Vector3d> points_D;
  std::vector<Eigen::Vector2d> pixels;
  bool coplanar = false;
};

std::vector<Eigen::Vector2d> ProjectAll(const PinholeRadtanCamera& camera, const Pose3& T_C_D,
                                        const std::vector<Eigen::Vector3d>& points_D) {
  std::vector<Eigen::Vector2d> pixels;
  for (const Eigen::Vector3d& X : points_D) pixels.push_back(*camera.Project(T_C_D * X));
  return pixels;
}

// A camera looking at the points' centroid from `distance`, at most `max_tilt` from the model
// z axis, with a random roll and a small random offset of the optical axis.
Pose3 LookAt(std::mt19937& rng, const Eigen::Vector3d& target, double distance, double max_tilt) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double tilt = max_tilt * u(rng);
  const double azimuth = 2.0 * kPi * u(rng);
  const Eigen::Vector3d dir(std::sin(tilt) * std::cos(azimuth), std::sin(tilt) * std::sin(azimuth),
                            -std::cos(tilt));
  const Eigen::Vector3d centre_D = target + distance * dir;
  Eigen::Vector3d z_C = (target - centre_D).normalized();
  std::normal_distribution<double> n(0.0, 0.05);
  z_C = (z_C + Eigen::Vector3d(n(rng), n(rng), n(rng))).normalized();
  Eigen::Vector3d x_C = z_C.unitOrthogonal();
  const double roll = 2.0 * kPi * u(rng);
  x_C = Eigen::AngleAxisd(roll, z_C) * x_C;
  Eigen::Matrix3d R_D_C;
  R_D_C << x_C, z_C.cross(x_C), z_C;
  return Pose3(Eigen::Quaterniond(R_D_C), centre_D).Inverse();
}

PinholeRadtanCamera RandomCamera(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double fx = 800.0 + 200.0 * u(rng);
  return PinholeRadtanCamera(
      1280, 1024, fx, fx * (1.0 + 0.02 * u(rng)), 640.0 + 20.0 * u(rng), 512.0 + 20.0 * u(rng),
      {-0.15 + 0.1 * u(rng), 0.05 * u(rng), 1e-3 * u(rng), 1e-3 * u(rng), 0.02 * u(rng)});
}

Problem RandomProblem(std::mt19937& rng, int n, bool coplanar) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Problem p;
  p.coplanar = coplanar;
  p.camera = RandomCamera(rng);
  while (true) {
    p.points_D.clear();
    for (int i = 0; i < n; ++i)
      p.points_D.emplace_back(u(rng), u(rng), coplanar ? 0.0 : 0.5 * u(rng));
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const auto& X : p.points_D) centroid += X / n;
    p.T_C_D = LookAt(rng, centroid, 4.0 + 2.0 * u(rng), 60.0 * kPi / 180.0);
    bool inside = true;
    for (const auto& X : p.points_D) {
      const auto uv = p.camera.Project(p.T_C_D * X);
      inside = inside && uv.has_value() && p.camera.InImage(*uv, 10.0);
    }
    if (inside) break;
  }
  p.pixels = ProjectAll(p.camera, p.T_C_D, p.points_D);
  return p;
}

struct CvPose {
  bool ok = false;
  Pose3 T_C_D;
};

Pose3 FromRvecTvec(const cv::Mat& rvec, const cv::Mat& tvec) {
  return Pose3(
      ExpQuaternion(Eigen::Vector3d(rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2))),
      Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)));
}

// cv::solvePnP(SOLVEPNP_ITERATIVE) on the same raw pixels. Its closed-form start (DLT) needs
// 6 points unless they are coplanar, so fewer non-coplanar points start from EPnP.
// With `start`, only OpenCV's LM runs, from there (useExtrinsicGuess).
CvPose SolveWithOpenCv(const std::vector<Eigen::Vector3d>& points_D,
                       const std::vector<Eigen::Vector2d>& pixels,
                       const PinholeRadtanCamera& camera, bool coplanar,
                       const std::optional<Pose3>& start = std::nullopt) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (const auto& X : points_D) object.emplace_back(X.x(), X.y(), X.z());
  for (const auto& uv : pixels) image.emplace_back(uv.x(), uv.y());
  const Eigen::Matrix3d K = camera.K();
  cv::Mat K_cv = (cv::Mat_<double>(3, 3) << K(0, 0), K(0, 1), K(0, 2), K(1, 0), K(1, 1), K(1, 2),
                  K(2, 0), K(2, 1), K(2, 2));
  const auto& d = camera.distortion();
  cv::Mat dist = (cv::Mat_<double>(1, 5) << d[0], d[1], d[2], d[3], d[4]);
  cv::Mat rvec, tvec;
  CvPose out;
  try {
    bool guess = false;
    if (start.has_value()) {
      const Eigen::Vector3d rvec_start = LogQuaternion(start->q);
      rvec = (cv::Mat_<double>(3, 1) << rvec_start.x(), rvec_start.y(), rvec_start.z());
      tvec = (cv::Mat_<double>(3, 1) << start->p.x(), start->p.y(), start->p.z());
      guess = true;
    } else if (!coplanar && points_D.size() < 6) {
      cv::solvePnP(object, image, K_cv, dist, rvec, tvec, false, cv::SOLVEPNP_EPNP);
      guess = true;
    }
    out.ok = cv::solvePnP(object, image, K_cv, dist, rvec, tvec, guess, cv::SOLVEPNP_ITERATIVE);
  } catch (const cv::Exception& e) {
    std::printf("OpenCV: %s\n", e.what());
    return out;
  }
  out.T_C_D = FromRvecTvec(rvec, tvec);
  return out;
}

double ReprojectionRms(const Problem& p, const Pose3& T) {
  double sum = 0.0;
  for (size_t i = 0; i < p.points_D.size(); ++i) {
    sum += (*p.camera.Project(T * p.points_D[i]) - p.pixels[i]).squaredNorm();
  }
  return std::sqrt(sum / p.points_D.size());
}

// ---------------------------------------------------------------------------------------------

// These two tests compare the minimiser with OpenCV's, which returns the lowest minimum it
// reaches, so the two-fold ambiguity check (step 2b) is off: with 4 coplanar points a twin can
// fit within 9 sigma^2 of an exact fit at the default 0.3 px (see SolvePnpAmbiguity).
PnpOptions LowestMinimumOptions() {
  PnpOptions options;
  options.ambiguity_chi2 = 0.0;
  return options;
}

TEST(SolvePnp, NoiseFreeRandomProblemsRecoverTheTruthAndAgreeWithOpenCv) {
  std::mt19937 rng(2024);
  double worst_truth_angle = 0, worst_truth_t = 0, worst_cv_angle = 0, worst_cv_t = 0;
  int trials = 0;
  for (bool coplanar : {true, false}) {
    for (int n = 4; n <= 12; ++n) {
      for (int k = 0; k < 25; ++k, ++trials) {
        const Problem p = RandomProblem(rng, n, coplanar);
        const PnpResult result =
            SolvePnp(p.points_D, p.pixels, p.camera, LowestMinimumOptions());
        ASSERT_TRUE(result.ok) << result.reason << " n=" << n << " coplanar=" << coplanar;
        const CvPose cv_pose = SolveWithOpenCv(p.points_D, p.pixels, p.camera, coplanar);
        ASSERT_TRUE(cv_pose.ok);
        const double truth_angle = RotationAngleBetween(result.T_C_D.q, p.T_C_D.q);
        const double truth_t = (result.T_C_D.p - p.T_C_D.p).norm();
        const double cv_angle = RotationAngleBetween(result.T_C_D.q, cv_pose.T_C_D.q);
        const double cv_t = (result.T_C_D.p - cv_pose.T_C_D.p).norm();
        EXPECT_LT(truth_angle, 1e-9) << "n=" << n << " coplanar=" << coplanar;
        EXPECT_LT(truth_t, 1e-9) << "n=" << n << " coplanar=" << coplanar;
        EXPECT_LT(cv_angle, 1e-6) << "n=" << n << " coplanar=" << coplanar;
        EXPECT_LT(cv_t, 1e-6) << "n=" << n << " coplanar=" << coplanar;
        EXPECT_LT(result.rms_px, 1e-8);
        worst_truth_angle = std::max(worst_truth_angle, truth_angle);
        worst_truth_t = std::max(worst_truth_t, truth_t);
        worst_cv_angle = std::max(worst_cv_angle, cv_angle);
        worst_cv_t = std::max(worst_cv_t, cv_t);
      }
    }
  }
  std::printf("noise-free, %d problems: vs truth %.2e rad %.2e m; vs OpenCV %.2e rad %.2e m\n",
              trials, worst_truth_angle, worst_truth_t, worst_cv_angle, worst_cv_t);
}

// With noise the cost has local minima (few points, near-planar ambiguity, a poor DLT start),
// and OpenCV's single start sometimes ends in a worse one than ours. Every time the two differ,
// OpenCV's minimum must have the higher cost, and OpenCV's own LM started from our answer
// (useExtrinsicGuess) must stay there: then both solve the same problem to the same minimum.
TEST(SolvePnp, NoisyRandomProblemsReachTheSameMinimumAsOpenCv) {
  std::mt19937 rng(77);
  std::normal_distribution<double> noise(0.0, 0.5);
  double worst_angle = 0, worst_t = 0, worst_refined_angle = 0, worst_refined_t = 0;
  int trials = 0, opencv_worse = 0;
  for (bool coplanar : {true, false}) {
    for (int n = 4; n <= 12; ++n) {
      for (int k = 0; k < 25; ++k, ++trials) {
        Problem p = RandomProblem(rng, n, coplanar);
        for (Eigen::Vector2d& uv : p.pixels) uv += Eigen::Vector2d(noise(rng), noise(rng));
        const PnpResult result =
            SolvePnp(p.points_D, p.pixels, p.camera, LowestMinimumOptions());
        ASSERT_TRUE(result.ok) << result.reason;
        EXPECT_NEAR(result.rms_px, ReprojectionRms(p, result.T_C_D), 1e-9);
        EXPECT_LE(result.rms_px, ReprojectionRms(p, p.T_C_D) + 1e-9);

        const CvPose cv_pose = SolveWithOpenCv(p.points_D, p.pixels, p.camera, coplanar);
        ASSERT_TRUE(cv_pose.ok);
        const double angle = RotationAngleBetween(result.T_C_D.q, cv_pose.T_C_D.q);
        const double dt = (result.T_C_D.p - cv_pose.T_C_D.p).norm();
        if (angle < 1e-6 && dt < 1e-6) {
          worst_angle = std::max(worst_angle, angle);
          worst_t = std::max(worst_t, dt);
          continue;
        }
        ++opencv_worse;
        EXPECT_LT(result.rms_px, ReprojectionRms(p, cv_pose.T_C_D) - 1e-9)
            << "n=" << n << " coplanar=" << coplanar;
        const CvPose refined =
            SolveWithOpenCv(p.points_D, p.pixels, p.camera, coplanar, result.T_C_D);
        ASSERT_TRUE(refined.ok);
        const double refined_angle = RotationAngleBetween(result.T_C_D.q, refined.T_C_D.q);
        const double refined_t = (result.T_C_D.p - refined.T_C_D.p).norm();
        EXPECT_LT(refined_angle, 1e-6) << "n=" << n << " coplanar=" << coplanar;
        EXPECT_LT(refined_t, 1e-6) << "n=" << n << " coplanar=" << coplanar;
        worst_refined_angle = std::max(worst_refined_angle, refined_angle);
        worst_refined_t = std::max(worst_refined_t, refined_t);
      }
    }
  }
  std::printf(
      "sigma 0.5 px, %d problems: %d agree with OpenCV to %.2e rad %.2e m; in %d OpenCV "
      "stopped in a worse local minimum, and from our answer it agrees to %.2e rad %.2e m\n",
      trials, trials - opencv_worse, worst_angle, worst_t, opencv_worse, worst_refined_angle,
      worst_refined_t);
  EXPECT_LE(opencv_worse, trials / 20);
}

// The dock's 6 coplanar lights seen by the simulated cameras along the default trajectory. Views
// whose planar twin fits within 9 sigma^2 at the default 0.3 px (few lights, 3 of them on the
// stem) are refused as ambiguous, and the truth must then be one of the two reported minima.
TEST(SolvePnp, DockLightsAlongTheDefaultTrajectory) {
  const Scenario scenario = test::DefaultScenario();
  const Calibration calibration = MakeCalibration(scenario);
  const DockingTrajectory trajectory(scenario.trajectory);
  std::vector<Eigen::Vector3d> lights_D;
  for (const DockLight& light : scenario.dock.lights) lights_D.push_back(light.p_D);
  int solved = 0, ambiguous = 0;
  for (const CameraCalibration& camera : calibration.cameras) {
    for (double t = 0.0; t <= scenario.duration_s; t += 0.5) {
      const Pose3 T_C_D = (trajectory.At(t).T_D_B * camera.T_B_C).Inverse();
      std::vector<Eigen::Vector3d> points;
      std::vector<Eigen::Vector2d> pixels;
      for (const Eigen::Vector3d& p_D : lights_D) {
        const auto uv = camera.intrinsics.Project(T_C_D * p_D);
        if (uv && camera.intrinsics.InImage(*uv)) {
          points.push_back(p_D);
          pixels.push_back(*uv);
        }
      }
      if (points.size() < 4) continue;
      bool collinear = true;
      for (const auto& X : points) collinear = collinear && std::abs(X.y()) < 1e-9;
      const PnpResult result = SolvePnp(points, pixels, camera.intrinsics);
      if (collinear) {
        EXPECT_FALSE(result.ok);
        continue;
      }
      if (!result.ok && result.reason.find("ambiguous") != std::string::npos) {
        ASSERT_EQ(result.ambiguous_T_C_D.size(), 2u);
        EXPECT_LT(std::min(RotationAngleBetween(result.ambiguous_T_C_D[0].q, T_C_D.q),
                           RotationAngleBetween(result.ambiguous_T_C_D[1].q, T_C_D.q)),
                  1e-9)
            << t;
        ++ambiguous;
        continue;
      }
      ASSERT_TRUE(result.ok) << result.reason << " t=" << t << " " << camera.name;
      EXPECT_LT(RotationAngleBetween(result.T_C_D.q, T_C_D.q), 1e-9) << t;
      EXPECT_LT((result.T_C_D.p - T_C_D.p).norm(), 1e-9) << t;
      ++solved;
    }
  }
  std::printf("dock lights along the default trajectory: %d solved, %d ambiguous\n", solved,
              ambiguous);
  EXPECT_GT(solved, 40);
  EXPECT_LE(ambiguous, solved / 5);
}

// Monte-Carlo: the spread of noisy solutions matches the reported covariance.
TEST(SolvePnp, CovarianceMatchesMonteCarloSpread) {
  const Scenario scenario = test::DefaultScenario();
  const CameraCalibration camera = MakeCalibration(scenario).cameras[0];
  std::vector<Eigen::Vector3d> lights_D;
  for (const DockLight& light : scenario.dock.lights) lights_D.push_back(light.p_D);
  // The stereo camera 3 m from the dock centre, looking down at it at 45 degrees.
  const Eigen::Vector3d centre_D(-2.1, 0.3, -2.1);
  const Eigen::Vector3d z_C = -centre_D.normalized();
  const Eigen::Vector3d x_C = Eigen::Vector3d::UnitZ().cross(z_C).normalized();
  Eigen::Matrix3d R_D_C;
  R_D_C << x_C, z_C.cross(x_C), z_C;
  const Pose3 T_C_D = Pose3(Eigen::Quaterniond(R_D_C), centre_D).Inverse();
  const auto pixels = ProjectAll(camera.intrinsics, T_C_D, lights_D);
  for (const auto& uv : pixels) ASSERT_TRUE(camera.intrinsics.InImage(uv));

  PnpOptions options;
  options.pixel_sigma = 0.3;
  const PnpResult reference = SolvePnp(lights_D, pixels, camera.intrinsics, options);
  ASSERT_TRUE(reference.ok) << reference.reason;
  const Eigen::Vector3d rvec_true = LogQuaternion(T_C_D.q);

  constexpr int kSamples = 2000;  // variance of a variance estimate: sqrt(2 / N) = 3 %
  std::mt19937 rng(99);
  std::normal_distribution<double> noise(0.0, options.pixel_sigma);
  std::vector<Eigen::Matrix<double, 6, 1>> samples, local_samples;
  for (int k = 0; k < kSamples; ++k) {
    auto noisy = pixels;
    for (auto& uv : noisy) uv += Eigen::Vector2d(noise(rng), noise(rng));
    const PnpResult result = SolvePnp(lights_D, noisy, camera.intrinsics, options);
    ASSERT_TRUE(result.ok) << result.reason;
    Eigen::Matrix<double, 6, 1> e, e_local;
    e << LogQuaternion(result.T_C_D.q) - rvec_true, result.T_C_D.p - T_C_D.p;
    e_local << LogQuaternion(result.T_C_D.q * T_C_D.q.conjugate()), result.T_C_D.p - T_C_D.p;
    samples.push_back(e);
    local_samples.push_back(e_local);
  }
  auto sample_covariance = [](const std::vector<Eigen::Matrix<double, 6, 1>>& s) {
    Eigen::Matrix<double, 6, 1> mean = Eigen::Matrix<double, 6, 1>::Zero();
    for (const auto& e : s) mean += e / s.size();
    Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
    for (const auto& e : s) C += (e - mean) * (e - mean).transpose() / (s.size() - 1.0);
    return C;
  };
  const Eigen::Matrix<double, 6, 6> C = sample_covariance(samples);
  const Eigen::Matrix<double, 6, 6> C_local = sample_covariance(local_samples);
  std::printf("PnP Monte-Carlo (%d samples) sample/reported variance, (rvec, t):", kSamples);
  for (int k = 0; k < 6; ++k) {
    const double ratio = C(k, k) / reference.covariance(k, k);
    const double ratio_local = C_local(k, k) / reference.covariance_local(k, k);
    std::printf(" %.3f", ratio);
    EXPECT_NEAR(ratio, 1.0, 0.15) << k;
    EXPECT_NEAR(ratio_local, 1.0, 0.15) << k;
  }
  std::printf("\n");
  // Whole matrix: normalized estimation error squared averages 6.
  double nees = 0.0;
  const Eigen::Matrix<double, 6, 6> information = reference.covariance.inverse();
  for (const auto& e : samples) nees += e.dot(information * e) / kSamples;
  std::printf("PnP mean NEES %.3f (expected 6)\n", nees);
  EXPECT_NEAR(nees, 6.0, 0.6);
}

// The default dock seen by the stereo camera 3 m from its centre at 45 degrees (as above).
struct DockView {
  CameraCalibration camera;
  std::vector<Eigen::Vector3d> lights_D;
  Pose3 T_C_D;
  std::vector<Eigen::Vector2d> pixels;
};

DockView DefaultDockView() {
  const Scenario scenario = test::DefaultScenario();
  DockView view;
  view.camera = MakeCalibration(scenario).cameras[0];
  for (const DockLight& light : scenario.dock.lights) view.lights_D.push_back(light.p_D);
  const Eigen::Vector3d centre_D(-2.1, 0.3, -2.1);
  const Eigen::Vector3d z_C = -centre_D.normalized();
  const Eigen::Vector3d x_C = Eigen::Vector3d::UnitZ().cross(z_C).normalized();
  Eigen::Matrix3d R_D_C;
  R_D_C << x_C, z_C.cross(x_C), z_C;
  view.T_C_D = Pose3(Eigen::Quaterniond(R_D_C), centre_D).Inverse();
  view.pixels = ProjectAll(view.camera.intrinsics, view.T_C_D, view.lights_D);
  return view;
}

Eigen::Matrix<double, 6, 1> LocalError(const Pose3& estimate, const Pose3& truth) {
  Eigen::Matrix<double, 6, 1> e;
  e << LogQuaternion(estimate.q * truth.q.conjugate()), estimate.p - truth.p;
  return e;
}

Eigen::Matrix<double, 6, 6> SampleCovariance(const std::vector<Eigen::Matrix<double, 6, 1>>& s) {
  Eigen::Matrix<double, 6, 1> mean = Eigen::Matrix<double, 6, 1>::Zero();
  for (const auto& e : s) mean += e / s.size();
  Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
  for (const auto& e : s) C += (e - mean) * (e - mean).transpose() / (s.size() - 1.0);
  return C;
}

TEST(SolvePnp, PerPixelCovariancesWeighThePixelsAndMatchTheSpread) {
  const DockView view = DefaultDockView();
  // One light smeared along u (3 px), another blurred (1.5 px round), the rest at 0.3 px.
  std::vector<Eigen::Matrix2d> covariances(view.pixels.size(), 0.09 * Eigen::Matrix2d::Identity());
  covariances[0] = Eigen::Vector2d(9.0, 0.09).asDiagonal();
  covariances[2] = 2.25 * Eigen::Matrix2d::Identity();
  PnpOptions options;
  options.pixel_sigma = 0.3;
  const PnpResult reference = SolvePnp(view.lights_D, view.pixels, view.camera.intrinsics, options,
                                       std::nullopt, covariances);
  ASSERT_TRUE(reference.ok) << reference.reason;
  EXPECT_NEAR(reference.chi2, 0.0, 1e-12);

  constexpr int kSamples = 1500;
  std::mt19937 rng(7);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Matrix<double, 6, 1>> weighted, unweighted;
  for (int k = 0; k < kSamples; ++k) {
    auto noisy = view.pixels;
    for (std::size_t i = 0; i < noisy.size(); ++i) {
      const Eigen::Matrix2d L = covariances[i].llt().matrixL();
      noisy[i] += L * Eigen::Vector2d(unit(rng), unit(rng));
    }
    const PnpResult w = SolvePnp(view.lights_D, noisy, view.camera.intrinsics, options,
                                 std::nullopt, covariances);
    const PnpResult u = SolvePnp(view.lights_D, noisy, view.camera.intrinsics, options);
    ASSERT_TRUE(w.ok && u.ok) << w.reason << u.reason;
    weighted.push_back(LocalError(w.T_C_D, view.T_C_D));
    unweighted.push_back(LocalError(u.T_C_D, view.T_C_D));
  }
  const Eigen::Matrix<double, 6, 6> C = SampleCovariance(weighted);
  for (int k = 0; k < 6; ++k) {
    EXPECT_NEAR(C(k, k) / reference.covariance_local(k, k), 1.0, 0.15) << k;
  }
  // Weighing by the claimed covariances beats treating every pixel alike.
  const Eigen::Matrix<double, 6, 6> C_unweighted = SampleCovariance(unweighted);
  const double position_variance = C.bottomRightCorner(3, 3).trace();
  const double rotation_variance = C.topLeftCorner(3, 3).trace();
  std::printf("PnP weighted / unweighted variance: position %.3f, rotation %.3f\n",
              position_variance / C_unweighted.bottomRightCorner(3, 3).trace(),
              rotation_variance / C_unweighted.topLeftCorner(3, 3).trace());
  EXPECT_LT(position_variance, 0.5 * C_unweighted.bottomRightCorner(3, 3).trace());
  EXPECT_LT(rotation_variance, 0.5 * C_unweighted.topLeftCorner(3, 3).trace());
}

TEST(SolvePnp, TheVarianceFactorWidensTheCovarianceOfPixelsNoisierThanClaimed) {
  const DockView view = DefaultDockView();
  const int n = static_cast<int>(view.pixels.size());
  PnpOptions options;
  options.pixel_sigma = 0.3;
  PnpOptions fixed = options;
  fixed.inflate_by_variance_factor = false;
  constexpr int kSamples = 1000;
  for (const double true_sigma : {0.3, 0.9}) {
    std::mt19937 rng(11);
    std::normal_distribution<double> noise(0.0, true_sigma);
    double mean_factor = 0.0, nees = 0.0, nees_fixed = 0.0;
    for (int k = 0; k < kSamples; ++k) {
      auto noisy = view.pixels;
      for (auto& uv : noisy) uv += Eigen::Vector2d(noise(rng), noise(rng));
      const PnpResult r = SolvePnp(view.lights_D, noisy, view.camera.intrinsics, options);
      const PnpResult f = SolvePnp(view.lights_D, noisy, view.camera.intrinsics, fixed);
      ASSERT_TRUE(r.ok && f.ok);
      EXPECT_EQ(r.dof, 2 * n - 6);
      EXPECT_NEAR(r.variance_factor, f.variance_factor, 1e-12);
      const auto e = LocalError(r.T_C_D, view.T_C_D);
      mean_factor += r.variance_factor / kSamples;
      nees += e.dot(r.covariance_local.inverse() * e) / kSamples;
      nees_fixed += e.dot(f.covariance_local.inverse() * e) / kSamples;
    }
    const double ratio = true_sigma * true_sigma / (options.pixel_sigma * options.pixel_sigma);
    std::printf("PnP, noise %.1f px claimed 0.3: mean variance factor %.2f, NEES %.2f (%.2f "
                "without the factor)\n",
                true_sigma, mean_factor, nees, nees_fixed);
    EXPECT_NEAR(mean_factor, ratio, 0.15 * ratio);
    EXPECT_NEAR(nees_fixed, 6.0 * ratio, 0.15 * 6.0 * ratio);
    if (ratio > 1.0) {
      // 9 times too confident without the factor; with it E[NEES] = 6 dof / (dof - 2) = 9.
      EXPECT_LT(nees, 12.0);
    } else {
      // Right as claimed: the factor only ever widens, a little (a fit that happens to be worse).
      EXPECT_GT(nees, 4.0);
      EXPECT_LT(nees, 6.3);
    }
  }
}

TEST(CameraInDockCovariance, MapsThePnpPerturbationToTheDockFramesTangentAsFiniteDifferences) {
  const Pose3 T_C_D(ExpQuaternion(Eigen::Vector3d(0.3, -0.7, 1.1)), Eigen::Vector3d(0.4, -0.2, 3.0));
  // Columns of the Jacobian by finite differences of T_D_C under each local perturbation.
  Eigen::Matrix<double, 6, 6> J;
  const Pose3 T_D_C = T_C_D.Inverse();
  constexpr double h = 1e-7;
  for (int k = 0; k < 6; ++k) {
    Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
    d(k) = h;
    const Pose3 perturbed(ExpQuaternion(d.head<3>()) * T_C_D.q, T_C_D.p + d.tail<3>());
    const Pose3 T = perturbed.Inverse();
    J.col(k) << (T.p - T_D_C.p) / h, LogQuaternion(T.q * T_D_C.q.conjugate()) / h;
  }
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Random();
  const Eigen::Matrix<double, 6, 6> P = A * A.transpose() + Eigen::Matrix<double, 6, 6>::Identity();
  const Eigen::Matrix<double, 6, 6> expected = J * P * J.transpose();
  EXPECT_TRUE(CameraInDockCovariance(T_C_D, P).isApprox(expected, 1e-6))
      << CameraInDockCovariance(T_C_D, P) << "\n\n" << expected;
}

// ---------------------------------------------------------------------------------------------
// Bad input and degenerate geometry: ok = false with a reason, never a wrong pose.

class SolvePnpFailures : public ::testing::Test {
 protected:
  void SetUp() override {
    std::mt19937 rng(5);
    p_ = RandomProblem(rng, 6, false);
  }
  Problem p_;
};

TEST_F(SolvePnpFailures, TooFewMismatchedOrNonFiniteInput) {
  const auto& X = p_.points_D;
  const auto& uv = p_.pixels;
  EXPECT_FALSE(SolvePnp({X[0], X[1]}, {uv[0], uv[1]}, p_.camera).ok);
  EXPECT_FALSE(SolvePnp({}, {}, p_.camera).ok);
  EXPECT_FALSE(SolvePnp(X, {uv.begin(), uv.end() - 1}, p_.camera).ok);
  auto bad_uv = uv;
  bad_uv[2].x() = std::numeric_limits<double>::quiet_NaN();
  const PnpResult nan = SolvePnp(X, bad_uv, p_.camera);
  EXPECT_FALSE(nan.ok);
  EXPECT_NE(nan.reason.find("NaN"), std::string::npos) << nan.reason;
  auto bad_X = X;
  bad_X[0].z() = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(SolvePnp(bad_X, uv, p_.camera).ok);
  PnpOptions options;
  options.pixel_sigma = 0.0;
  EXPECT_FALSE(SolvePnp(X, uv, p_.camera, options).ok);
}

TEST_F(SolvePnpFailures, PixelCovariancesOfTheWrongCountOrNotPositiveDefinite) {
  PnpOptions options;
  std::vector<Eigen::Matrix2d> covariances(p_.pixels.size(), Eigen::Matrix2d::Identity());
  covariances.pop_back();
  PnpResult r = SolvePnp(p_.points_D, p_.pixels, p_.camera, options, std::nullopt, covariances);
  EXPECT_FALSE(r.ok);
  EXPECT_THAT(r.reason, ::testing::HasSubstr("size mismatch"));
  covariances.push_back(Eigen::Matrix2d::Identity());
  covariances[1] << 1.0, 2.0, 2.0, 1.0;  // indefinite
  r = SolvePnp(p_.points_D, p_.pixels, p_.camera, options, std::nullopt, covariances);
  EXPECT_FALSE(r.ok);
  EXPECT_THAT(r.reason, ::testing::HasSubstr("pixel covariance 1 is not positive definite"));
  covariances[1] << 1.0, std::nan(""), std::nan(""), 1.0;
  r = SolvePnp(p_.points_D, p_.pixels, p_.camera, options, std::nullopt, covariances);
  EXPECT_FALSE(r.ok);
  covariances[1] = Eigen::Matrix2d::Identity();
  r = SolvePnp(p_.points_D, p_.pixels, p_.camera, options, std::nullopt, covariances);
  EXPECT_TRUE(r.ok) << r.reason;
}

TEST_F(SolvePnpFailures, CollinearModelPoints) {
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 6; ++i) line.emplace_back(0.3 * i, 0.1 * i, -0.05 * i);
  const auto pixels = ProjectAll(p_.camera, p_.T_C_D, line);
  const PnpResult result = SolvePnp(line, pixels, p_.camera);
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.reason.find("collinear"), std::string::npos) << result.reason;
}

TEST_F(SolvePnpFailures, ThreePointsAreAmbiguousWithoutAStartAndRefinedWithOne) {
  const std::vector<Eigen::Vector3d> X(p_.points_D.begin(), p_.points_D.begin() + 3);
  const std::vector<Eigen::Vector2d> uv(p_.pixels.begin(), p_.pixels.begin() + 3);
  const PnpResult ambiguous = SolvePnp(X, uv, p_.camera);
  EXPECT_FALSE(ambiguous.ok);
  EXPECT_NE(ambiguous.reason.find("ambiguous"), std::string::npos) << ambiguous.reason;

  Pose3 start = p_.T_C_D;
  start.q = ExpQuaternion(Eigen::Vector3d(0.03, -0.02, 0.04)) * start.q;
  start.p += Eigen::Vector3d(0.05, -0.05, 0.1);
  const PnpResult refined = SolvePnp(X, uv, p_.camera, {}, start);
  ASSERT_TRUE(refined.ok) << refined.reason;
  EXPECT_LT(RotationAngleBetween(refined.T_C_D.q, p_.T_C_D.q), 1e-9);
  EXPECT_LT((refined.T_C_D.p - p_.T_C_D.p).norm(), 1e-9);
  EXPECT_GT(refined.iterations, 0);
}

TEST_F(SolvePnpFailures, NoConvergenceWithinTheIterationBudget) {
  const std::vector<Eigen::Vector3d> X(p_.points_D.begin(), p_.points_D.begin() + 3);
  const std::vector<Eigen::Vector2d> uv(p_.pixels.begin(), p_.pixels.begin() + 3);
  Pose3 start = p_.T_C_D;
  start.q = ExpQuaternion(Eigen::Vector3d(0.1, -0.05, 0.08)) * start.q;
  start.p += Eigen::Vector3d(0.2, -0.2, 0.4);
  PnpOptions options;
  options.max_iterations = 1;
  const PnpResult result = SolvePnp(X, uv, p_.camera, options, start);
  EXPECT_FALSE(result.ok);
  EXPECT_EQ(result.reason, "no convergence");
}

// A coplanar model has an exact mirror solution with every point behind the camera:
// R' = R diag(-1, -1, 1), t' = -t gives x_C' = -x_C and the same pixels.
TEST_F(SolvePnpFailures, PointsBehindTheCameraAndTheMirrorStartIsNotATrap) {
  std::mt19937 rng(8);
  const Problem planar = RandomProblem(rng, 6, true);
  Pose3 mirror(
      planar.T_C_D.q * Eigen::Quaterniond(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitZ())),
      -planar.T_C_D.p);
  for (const auto& X : planar.points_D) ASSERT_LT((mirror * X).z(), 0.0);

  const std::vector<Eigen::Vector3d> X(planar.points_D.begin(), planar.points_D.begin() + 3);
  const std::vector<Eigen::Vector2d> uv(planar.pixels.begin(), planar.pixels.begin() + 3);
  const PnpResult behind = SolvePnp(X, uv, planar.camera, {}, mirror);
  EXPECT_FALSE(behind.ok);
  EXPECT_NE(behind.reason.find("behind"), std::string::npos) << behind.reason;

  // With 6 points the closed-form starts win over the bad start.
  const PnpResult result = SolvePnp(planar.points_D, planar.pixels, planar.camera, {}, mirror);
  ASSERT_TRUE(result.ok) << result.reason;
  EXPECT_LT(RotationAngleBetween(result.T_C_D.q, planar.T_C_D.q), 1e-9);
}

// P3P's "danger cylinder" (Thompson 1966): with the camera centre on the cylinder through the
// three points, perpendicular to their plane, the Jacobian is singular.
TEST_F(SolvePnpFailures, SingularNormalEquationsOnTheDangerCylinder) {
  const double angles[] = {0.0, 100.0, 220.0};
  std::vector<Eigen::Vector3d> X;
  for (double a : angles) X.emplace_back(std::cos(a * kPi / 180.0), std::sin(a * kPi / 180.0), 0.0);
  const double a = 300.0 * kPi / 180.0;
  const Eigen::Vector3d centre_D(std::cos(a), std::sin(a), -3.0);
  const Eigen::Vector3d z_C = (Eigen::Vector3d::Zero() - centre_D).normalized();
  const Eigen::Vector3d x_C = z_C.unitOrthogonal();
  Eigen::Matrix3d R_D_C;
  R_D_C << x_C, z_C.cross(x_C), z_C;
  const Pose3 T_C_D = Pose3(Eigen::Quaterniond(R_D_C), centre_D).Inverse();
  const auto uv = ProjectAll(p_.camera, T_C_D, X);
  const PnpResult result = SolvePnp(X, uv, p_.camera, {}, T_C_D);
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.reason.find("singular"), std::string::npos) << result.reason;

  // Off the cylinder the same three points are fine.
  const Pose3 T_off = Pose3(Eigen::Quaterniond(R_D_C), Eigen::Vector3d(0.3, 0.2, -3.0)).Inverse();
  const PnpResult off = SolvePnp(X, ProjectAll(p_.camera, T_off, X), p_.camera, {}, T_off);
  EXPECT_TRUE(off.ok) << off.reason;
}

// ---------------------------------------------------------------------------------------------
// The two-fold ambiguity of a planar target (step 2b), on the frame where it was found: the
// default scenario's mono camera at t = 27.5 s, 2.5 m above the deck looking nearly straight
// down, sees the stem lights 1, 2, 4 (collinear) and the bar light 3. The pixels are the light
// detector's centroids on the rendered image (detections.csv of `auvdock frontend`). The plane
// tilted the other way (21 deg of roll, 0.9 m across the dock) fits them 0.1 px^2 better than the
// true pose, and the solver used to return it.

struct StemAndOneBarLight {
  CameraCalibration camera;
  std::vector<Eigen::Vector3d> points_D;
  std::vector<Eigen::Vector2d> pixels;
  Pose3 T_C_D_true;       // the ground truth at t = 27.5 s
  Pose3 T_C_D_predicted;  // the ground truth 0.1 s earlier: what tracking predicts
};

StemAndOneBarLight MakeStemAndOneBarLight() {
  const Scenario scenario = test::DefaultScenario();
  const Calibration calibration = MakeCalibration(scenario);
  const DockingTrajectory trajectory(scenario.trajectory);
  StemAndOneBarLight view;
  view.camera = *calibration.FindCameraByRole(CameraRole::kMono);
  const int ids[] = {4, 3, 2, 1};
  view.pixels = {{344.6086647053071, 267.5940199749991},
                 {222.5568302291267, 268.2067541410845},
                 {345.2474492103146, 369.34529842722975},
                 {346.32068341040815, 470.40839314548697}};
  for (int id : ids) view.points_D.push_back(scenario.dock.FindLight(id)->p_D);
  view.T_C_D_true = (trajectory.At(27.5).T_D_B * view.camera.T_B_C).Inverse();
  view.T_C_D_predicted = (trajectory.At(27.4).T_D_B * view.camera.T_B_C).Inverse();
  return view;
}

TEST(SolvePnpAmbiguity, PlanarTwinThatFitsAsWellIsRefusedWithoutAPrediction) {
  const StemAndOneBarLight view = MakeStemAndOneBarLight();
  PnpOptions options;
  options.pixel_sigma = view.camera.pixel_noise_px;
  // The truth fits at the noise level: these are honest pixels, not an outlier.
  ASSERT_LT(ReprojectionRms(
                {view.camera.intrinsics, view.T_C_D_true, view.points_D, view.pixels, true},
                view.T_C_D_true),
            options.pixel_sigma);

  const PnpResult result = SolvePnp(view.points_D, view.pixels, view.camera.intrinsics, options);
  EXPECT_FALSE(result.ok) << "returned a pose "
                          << RotationAngleBetween(result.T_C_D.q, view.T_C_D_true.q)
                          << " rad from the truth";
  EXPECT_NE(result.reason.find("ambiguous"), std::string::npos) << result.reason;
  // Both minima are reported: the true one and its twin, 21 deg away.
  ASSERT_EQ(result.ambiguous_T_C_D.size(), 2u);
  const double angle0 = RotationAngleBetween(result.ambiguous_T_C_D[0].q, view.T_C_D_true.q);
  const double angle1 = RotationAngleBetween(result.ambiguous_T_C_D[1].q, view.T_C_D_true.q);
  EXPECT_LT(std::min(angle0, angle1), 0.02);
  EXPECT_NEAR(std::max(angle0, angle1), 0.37, 0.03);
}

TEST(SolvePnpAmbiguity, ThePredictionChoosesTheTwinNearestToIt) {
  const StemAndOneBarLight view = MakeStemAndOneBarLight();
  PnpOptions options;
  options.pixel_sigma = view.camera.pixel_noise_px;
  const PnpResult result = SolvePnp(view.points_D, view.pixels, view.camera.intrinsics, options,
                                    view.T_C_D_predicted);
  ASSERT_TRUE(result.ok) << result.reason;
  EXPECT_LT(RotationAngleBetween(result.T_C_D.q, view.T_C_D_true.q), 0.02);
  // The body (the camera 0.3 m below it) within 5 cm of the truth, instead of 0.9 m.
  EXPECT_LT((result.T_C_D.Inverse().p - view.T_C_D_true.Inverse().p).norm(), 0.05);
  EXPECT_EQ(result.ambiguous_T_C_D.size(), 2u);  // the choice is recorded

  // A prediction halfway between the twins chooses neither.
  ASSERT_EQ(result.ambiguous_T_C_D.size(), 2u);
  Pose3 halfway = result.ambiguous_T_C_D[0];
  halfway.q = result.ambiguous_T_C_D[0].q.slerp(0.5, result.ambiguous_T_C_D[1].q);
  const PnpResult undecided =
      SolvePnp(view.points_D, view.pixels, view.camera.intrinsics, options, halfway);
  EXPECT_FALSE(undecided.ok);
  EXPECT_NE(undecided.reason.find("does not choose"), std::string::npos) << undecided.reason;
}

// ---------------------------------------------------------------------------------------------
// OpenCV's sample chessboards (Debian package opencv-doc).

constexpr const char* kOpenCvDataDir = "/usr/share/doc/opencv-doc/examples/data";

// The file itself, or a decompressed copy of file.gz in `scratch`; "" if neither exists.
std::string LocateDataFile(const std::string& name, const test::TempDir& scratch) {
  const std::string plain = std::string(kOpenCvDataDir) + "/" + name;
  if (fs::exists(plain)) return plain;
  if (fs::exists(plain + ".gz")) {
    const std::string out = scratch / name;
    const std::string command = "gzip -dc '" + plain + ".gz' > '" + out + "'";
    if (std::system(command.c_str()) == 0) return out;
  }
  return "";
}

TEST(SolvePnpChessboard, OpenCvSampleViewsAgreeWithOpenCvAndTheCalibrationExtrinsics) {
  test::TempDir scratch;
  const std::string yml = LocateDataFile("left_intrinsics.yml", scratch);
  if (yml.empty()) {
    GTEST_SKIP() << "opencv-doc sample data not found in " << kOpenCvDataDir
                 << " (apt-get install opencv-doc)";
  }
  cv::FileStorage fs_yml(yml, cv::FileStorage::READ);
  ASSERT_TRUE(fs_yml.isOpened());
  cv::Mat K_cv, dist_cv, extrinsics;
  fs_yml["camera_matrix"] >> K_cv;
  fs_yml["distortion_coefficients"] >> dist_cv;
  fs_yml["extrinsic_parameters"] >> extrinsics;
  const double square = static_cast<double>(fs_yml["square_size"]);
  const int board_w = static_cast<int>(fs_yml["board_width"]);
  const int board_h = static_cast<int>(fs_yml["board_height"]);
  ASSERT_EQ(board_w, 9);
  ASSERT_EQ(board_h, 6);
  ASSERT_NEAR(square, 0.025, 1e-6);  // metres: the extrinsics' tvec are in metres too
  ASSERT_EQ(extrinsics.rows, 13);
  ASSERT_EQ(extrinsics.cols, 6);
  const PinholeRadtanCamera camera(
      static_cast<int>(fs_yml["image_width"]), static_cast<int>(fs_yml["image_height"]),
      K_cv.at<double>(0, 0), K_cv.at<double>(1, 1), K_cv.at<double>(0, 2), K_cv.at<double>(1, 2),
      {dist_cv.at<double>(0), dist_cv.at<double>(1), dist_cv.at<double>(2), dist_cv.at<double>(3),
       dist_cv.at<double>(4)});

  std::vector<Eigen::Vector3d> board_D;
  std::vector<cv::Point3d> board_cv;
  for (int i = 0; i < board_h; ++i) {
    for (int j = 0; j < board_w; ++j) {
      board_D.emplace_back(j * square, i * square, 0.0);
      board_cv.emplace_back(j * square, i * square, 0.0);
    }
  }

  // The 13 views of the calibration, in order: left01..left14 without left10.
  const int views[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14};
  double worst_cv_angle = 0, worst_cv_t = 0, worst_ref_angle = 0, worst_ref_t = 0;
  int compared = 0;
  for (int v = 0; v < 13; ++v) {
    char name[32];
    std::snprintf(name, sizeof(name), "left%02d.jpg", views[v]);
    const std::string path = LocateDataFile(name, scratch);
    ASSERT_FALSE(path.empty()) << name;
    const cv::Mat gray = cv::imread(path, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(gray.empty()) << name;
    std::vector<cv::Point2f> corners;
    const bool found = cv::findChessboardCorners(
        gray, cv::Size(board_w, board_h), corners,
        cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK);
    ASSERT_TRUE(found) << name;
    cv::cornerSubPix(gray, corners, cv::Size(11, 11), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30, 1e-4));
    std::vector<Eigen::Vector2d> pixels;
    std::vector<cv::Point2d> pixels_cv;
    for (const cv::Point2f& c : corners) {
      pixels.emplace_back(c.x, c.y);
      pixels_cv.emplace_back(c.x, c.y);
    }

    const PnpResult result = SolvePnp(board_D, pixels, camera);
    ASSERT_TRUE(result.ok) << name << ": " << result.reason;
    cv::Mat rvec, tvec;
    ASSERT_TRUE(cv::solvePnP(board_cv, pixels_cv, K_cv, dist_cv, rvec, tvec, false,
                             cv::SOLVEPNP_ITERATIVE));
    const Pose3 T_cv = FromRvecTvec(rvec, tvec);
    const double cv_angle = RotationAngleBetween(result.T_C_D.q, T_cv.q);
    const double cv_t = (result.T_C_D.p - T_cv.p).norm();
    EXPECT_LT(cv_angle, 1e-6) << name;
    EXPECT_LT(cv_t, 1e-6) << name;

    const cv::Mat row = extrinsics.row(v);
    const Pose3 T_ref(
        ExpQuaternion(Eigen::Vector3d(row.at<double>(0), row.at<double>(1), row.at<double>(2))),
        Eigen::Vector3d(row.at<double>(3), row.at<double>(4), row.at<double>(5)));
    const double ref_angle = RotationAngleBetween(result.T_C_D.q, T_ref.q);
    const double ref_t = (result.T_C_D.p - T_ref.p).norm();
    std::printf(
        "%s: rms %.3f px, %d it; vs OpenCV %.1e rad %.1e m; vs calibration %.1e rad %.1e m\n", name,
        result.rms_px, result.iterations, cv_angle, cv_t, ref_angle, ref_t);
    EXPECT_LT(ref_angle, 1e-3) << name;
    EXPECT_LT(ref_t, 1e-3) << name;
    worst_cv_angle = std::max(worst_cv_angle, cv_angle);
    worst_cv_t = std::max(worst_cv_t, cv_t);
    worst_ref_angle = std::max(worst_ref_angle, ref_angle);
    worst_ref_t = std::max(worst_ref_t, ref_t);
    ++compared;
  }
  EXPECT_EQ(compared, 13);
  std::printf("chessboards: vs OpenCV %.2e rad %.2e m; vs calibration %.2e rad %.2e m\n",
              worst_cv_angle, worst_cv_t, worst_ref_angle, worst_ref_t);
}

}  // namespace
}  // namespace auvdock
