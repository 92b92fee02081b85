// End-to-end tests of `auvdock pnp` and `auvdock frontend`.
#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "auvdock/geometry/so3.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/csv.h"
#include "auvdock/io/tum_io.h"
#include "auvdock/sim/scenario.h"
#include "tests/testing/run_command.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_scenarios.h"

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

namespace auvdock {
namespace {

class PnpCli : public ::testing::Test {
 protected:
  void SetUp() override {
    calibration_ = MakeCalibration(test::DefaultScenario());
    calib_path_ = tmp_ / "calibration.yaml";
    SaveCalibration(calibration_, calib_path_);
    T_C_D_ = Pose3(ExpQuaternion(Eigen::Vector3d(0.2, -0.1, 0.05)), Eigen::Vector3d(0.1, -0.2, 3.0));
  }
  // CORR.csv of the dock lights (plus one off-plane point) seen by cam2 at T_C_D_.
  std::string WritePoints(int n, const std::string& extra = "") {
    std::string text = "X,Y,Z,u,v\n";
    const std::vector<Eigen::Vector3d> points = {{-0.75, 0, 0}, {-0.25, 0, 0}, {0.25, 0, 0},
                                                 {0.75, -0.6, 0}, {0.75, 0, 0}, {0.75, 0.6, 0},
                                                 {0.1, 0.3, -0.2}};
    for (int i = 0; i < n; ++i) {
      const auto uv = calibration_.cameras[2].intrinsics.Project(T_C_D_ * points[i]);
      text += FormatDouble(points[i].x()) + "," + FormatDouble(points[i].y()) + "," +
              FormatDouble(points[i].z()) + "," + FormatDouble(uv->x()) + "," +
              FormatDouble(uv->y()) + "\n";
    }
    const std::string path = tmp_ / "corr.csv";
    test::WriteTextFile(path, text + extra);
    return path;
  }
  test::TempDir tmp_;
  Calibration calibration_;
  std::string calib_path_;
  Pose3 T_C_D_;
};

TEST_F(PnpCli, SolvesAKnownPoseAndPrintsOneJsonObject) {
  const auto r = test::RunAuvdock(
      {"pnp", "--calib", calib_path_, "--camera", "cam2", "--points", WritePoints(7)});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(j.at("t")[i].get<double>(), T_C_D_.p[i], 1e-9);
  const Eigen::Matrix3d R = T_C_D_.R();
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(j.at("R")[i].get<double>(), R(i / 3, i % 3), 1e-9);
  const Eigen::Vector3d rvec = LogQuaternion(T_C_D_.q);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(j.at("rvec")[i].get<double>(), rvec[i], 1e-9);
  ASSERT_EQ(j.at("covariance_6x6").size(), 36u);
  EXPECT_GT(j.at("covariance_6x6")[0].get<double>(), 0.0);
  EXPECT_LT(j.at("rms_px").get<double>(), 1e-6);
}

TEST_F(PnpCli, BadInputIsOneLineAndExitTwo) {
  auto expect_error = [&](const std::vector<std::string>& args, const std::string& needle) {
    const auto r = test::RunAuvdock(args);
    EXPECT_EQ(r.exit_status, 2) << r.out;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_THAT(r.err, HasSubstr(needle));
  };
  expect_error({"pnp", "--calib", calib_path_, "--camera", "cam2", "--points", WritePoints(2)},
               "at least 3");
  expect_error({"pnp", "--calib", calib_path_, "--camera", "cam2", "--points",
                WritePoints(5, "0.1,0.2,0,nan,3\n")},
               "line 7");
  expect_error({"pnp", "--calib", calib_path_, "--points", WritePoints(5)}, "--camera");
  expect_error({"pnp", "--calib", calib_path_, "--camera", "cam9", "--points", WritePoints(5)},
               "cam9");
  const std::string no_distortion = tmp_ / "opencv.yml";
  test::WriteTextFile(no_distortion,
                      "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n"
                      "   rows: 3\n   cols: 3\n   dt: d\n   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n");
  expect_error({"pnp", "--calib", no_distortion, "--points", WritePoints(5)},
               "distortion_coefficients");
}

TEST_F(PnpCli, PerPointCovariancesWeighThePixelsAndABadOneNamesItsLine) {
  // Seven correspondences, the first pixel 4 px off. Claimed at 0.3 px it pulls the pose and
  // the fit's variance factor widens the covariance; claimed at 20 px it hardly counts.
  auto write = [&](double first_sigma, const std::string& extra) {
    std::string text = "X,Y,Z,u,v,cov_uu,cov_uv,cov_vv\n";
    const std::vector<Eigen::Vector3d> points = {{-0.75, 0, 0}, {-0.25, 0, 0}, {0.25, 0, 0},
                                                 {0.75, -0.6, 0}, {0.75, 0, 0}, {0.75, 0.6, 0},
                                                 {0.1, 0.3, -0.2}};
    for (std::size_t i = 0; i < points.size(); ++i) {
      Eigen::Vector2d uv = *calibration_.cameras[2].intrinsics.Project(T_C_D_ * points[i]);
      if (i == 0) uv.x() += 4.0;
      const double s = i == 0 ? first_sigma : 0.3;
      text += FormatDouble(points[i].x()) + "," + FormatDouble(points[i].y()) + "," +
              FormatDouble(points[i].z()) + "," + FormatDouble(uv.x()) + "," +
              FormatDouble(uv.y()) + "," + FormatDouble(s * s) + ",0," + FormatDouble(s * s) +
              "\n";
    }
    const std::string path = tmp_ / ("cov_" + std::to_string(first_sigma) + ".csv");
    test::WriteTextFile(path, text + extra);
    return path;
  };
  auto solve = [&](const std::string& path) {
    const auto r = test::RunAuvdock({"pnp", "--calib", calib_path_, "--camera", "cam2",
                                     "--points", path});
    EXPECT_EQ(r.exit_status, 0) << r.err;
    return nlohmann::json::parse(r.out);
  };
  const auto trusted = solve(write(0.3, ""));
  const auto doubted = solve(write(20.0, ""));
  auto position_error = [&](const nlohmann::json& j) {
    return (Eigen::Vector3d(j.at("t")[0], j.at("t")[1], j.at("t")[2]) - T_C_D_.p).norm();
  };
  EXPECT_LT(position_error(doubted), 0.2 * position_error(trusted));
  EXPECT_GT(trusted.at("variance_factor").get<double>(), 3.0);
  EXPECT_TRUE(trusted.at("covariance_scaled_by_variance_factor").get<bool>());
  EXPECT_LT(doubted.at("variance_factor").get<double>(), 1.0);
  EXPECT_FALSE(doubted.at("covariance_scaled_by_variance_factor").get<bool>());
  EXPECT_EQ(trusted.at("dof").get<int>(), 8);

  const auto r = test::RunAuvdock({"pnp", "--calib", calib_path_, "--camera", "cam2", "--points",
                                   write(0.3, "0.1,0.2,0,300,200,1,2,1\n")});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_THAT(r.err, AllOf(HasSubstr("line 9"), HasSubstr("not positive definite")));
}

TEST_F(PnpCli, AcceptsOpenCvCalibrationFiles) {
  const std::string path = tmp_ / "opencv.yml";
  const auto& k = calibration_.cameras[2].intrinsics;
  char text[1024];
  std::snprintf(text, sizeof(text),
                "%%YAML:1.0\n---\nimage_width: %d\nimage_height: %d\ncamera_matrix: !!opencv-matrix\n"
                "   rows: 3\n   cols: 3\n   dt: d\n   data: [ %.17g, 0., %.17g, 0., %.17g, %.17g, 0., 0., 1. ]\n"
                "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n   dt: d\n"
                "   data: [ %.17g, %.17g, %.17g, %.17g, %.17g ]\n",
                k.width(), k.height(), k.fx(), k.cx(), k.fy(), k.cy(), k.distortion()[0],
                k.distortion()[1], k.distortion()[2], k.distortion()[3], k.distortion()[4]);
  test::WriteTextFile(path, text);
  const auto r = test::RunAuvdock({"pnp", "--calib", path, "--points", WritePoints(6)});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(j.at("t")[i].get<double>(), T_C_D_.p[i], 1e-9);
}

TEST(FrontendCli, WritesDetectionsStagesAndPosesThatEvaluate) {
  test::TempDir tmp;
  const std::string scenario = tmp / "s.yaml";
  // 2 s of the default run (the stereo-only stage) at full resolution.
  test::WriteTextFile(scenario, "name: short\nduration_s: 2.0\ndock: " +
                                    test::SourcePath("data/docks/t_shape.yaml") + "\n");
  const std::string ds = tmp / "ds", out = tmp / "fe";
  ASSERT_EQ(test::RunAuvdock({"simulate", "--scenario", scenario, "--out", ds, "--quiet"}).exit_status, 0);
  const auto r = test::RunAuvdock({"frontend", "--dataset", ds, "--out", out, "--quiet"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  for (const char* f : {"detections.csv", "per_frame.tum", "per_frame_stereo.tum",
                        "per_frame_mono.tum", "stages.csv"}) {
    EXPECT_TRUE(fs::exists(out + "/" + f)) << f;
  }
  EXPECT_THAT(test::ReadTextFile(out + "/stages.csv"), HasSubstr("stereo_only"));
  const Trajectory poses = ReadTumTrajectory(out + "/per_frame.tum");
  EXPECT_GE(poses.size(), 18u);  // nearly every one of the 21 frames
  const auto e = test::RunAuvdock(
      {"evaluate", "--dataset", ds, "--estimate", out + "/per_frame.tum", "--json"});
  ASSERT_EQ(e.exit_status, 0) << e.err;
  // The first 2 s are stereo at 8-10 m over a 0.25 m baseline: depth sigma ~ z^2 sqrt(2)
  // sigma_px / (f b) ~ 0.3 m, so this is a sanity bound, not an accuracy target.
  EXPECT_LT(nlohmann::json::parse(e.out).at("pos_rmse_m").get<double>(), 0.6);
  // A second run into the same, now non-empty, folder is refused.
  EXPECT_EQ(test::RunAuvdock({"frontend", "--dataset", ds, "--out", out}).exit_status, 2);
}

}  // namespace
}  // namespace auvdock
