// End-to-end: a navigator's log without cameras (IMU, depth, DVL, acoustic fixes; the simulator's
// dataset with its cameras taken out of the calibration). `run` and `smooth` make their own
// states at --state-rate-hz over the IMU's span, start from the fixes and the DVL's path, and
// estimate every state after the start; the summary says why no state had vision.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <nlohmann/json.hpp>

#include "tests/testing/run_command.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_scenarios.h"

using ::testing::HasSubstr;

namespace auvdock {
namespace {

// A navigator's log: the simulator's dataset (duration_s of the default approach, from
// detections) with its cameras, and without with_fixes its acoustic sensor, taken out of the
// calibration. Returns the dataset folder.
// extra_scenario: more scenario keys (e.g. a heading sensor).
std::string NavigatorsLog(const test::TempDir& tmp, double duration_s, bool with_fixes,
                          const std::string& extra_scenario = "") {
  const std::string dataset =
      test::SimulateDetections(tmp.path(), "nav", duration_s, extra_scenario);
  YAML::Node calibration = YAML::LoadFile(dataset + "/calibration.yaml");
  calibration.remove("cameras");
  if (!with_fixes) calibration.remove("acoustic");
  YAML::Emitter out;
  out << calibration;
  test::WriteTextFile(dataset + "/calibration.yaml", out.c_str());
  return dataset;
}

// A --start file: the pose and velocity given, sigmas 0.1 m, 0.5 deg tilt, 1 deg heading,
// 0.05 m/s, at the simulator's first IMU sample.
void WriteStart(const std::string& path, const std::string& p_D, const std::string& rpy_deg,
                const std::string& v_D) {
  test::WriteTextFile(path, "t_ns: 1700000000000000000\np_D: [" + p_D + "]\nrpy_deg: [" + rpy_deg +
                                "]\nv_D: [" + v_D +
                                "]\nposition_sigma_m: 0.1\ntilt_sigma_deg: 0.5\n"
                                "heading_sigma_deg: 1.0\nvelocity_sigma_mps: 0.05\n");
}

TEST(WithoutCamerasCli, RunAndSmoothMakeTheirOwnStates) {
  test::TempDir tmp;
  const std::string dataset = NavigatorsLog(tmp, 30.0, /*with_fixes=*/true);
  ASSERT_FALSE(::testing::Test::HasFailure());

  for (const std::string command : {"run", "smooth"}) {
    const std::string result = tmp / (command + "_out");
    const auto r = test::RunAuvdock(
        {command, "--dataset", dataset, "--out", result, "--quiet", "--state-rate-hz", "5"});
    ASSERT_EQ(r.exit_status, 0) << command << ": " << r.err;
    EXPECT_THAT(r.out, HasSubstr("no camera in the calibration")) << command;
    const nlohmann::json summary =
        nlohmann::json::parse(test::ReadTextFile(result + "/summary.json"));
    // 30 s of IMU at 5 states a second, the first one period after the first sample.
    EXPECT_NEAR(summary["frames"].get<int>(), 150, 1) << command;
    EXPECT_GT(summary["estimates"].get<int>(), 100) << command;  // after the acoustic start
    EXPECT_EQ(summary["acoustic_starts"].get<int>(), 1) << command;
  }
  const auto bad = test::RunAuvdock(
      {"run", "--dataset", dataset, "--out", tmp / "bad", "--quiet", "--state-rate-hz", "0"});
  EXPECT_EQ(bad.exit_status, 2);
}

// A navigator's log without cameras and without fixes (IMU, depth, DVL): nothing starts the
// window, every state says why; with --start (the true state at the first state's time, as an
// INS would give it) every state is estimated from it, the first one at the given pose. A start
// file with a bad key names the file and the key, exit 2.
TEST(WithoutCamerasCli, AGivenStartStartsTheWindow) {
  test::TempDir tmp;
  const std::string dataset = NavigatorsLog(tmp, 20.0, /*with_fixes=*/false);
  ASSERT_FALSE(::testing::Test::HasFailure());

  const auto without =
      test::RunAuvdock({"run", "--dataset", dataset, "--out", tmp / "without", "--quiet"});
  ASSERT_EQ(without.exit_status, 0) << without.err;
  EXPECT_THAT(without.out, HasSubstr(": 0 estimates"));
  EXPECT_THAT(test::ReadTextFile(tmp / "without/decisions.csv"), HasSubstr("not initialised"));

  // The simulator's first true state (t = its first IMU sample): roll, pitch, yaw of
  // q = (0.99660, -0.00092, 0.01121, 0.08162) and its velocity.
  const std::string start = tmp / "start.yaml";
  WriteStart(start, "-8.0, 1.0738800516653348, -4.428703411195086", "0.0, 1.2884, 9.3639",
             "0.49613893835683387, 0.026255517880197796, 0.038000379807131134");
  const auto with = test::RunAuvdock(
      {"run", "--dataset", dataset, "--out", tmp / "with", "--quiet", "--start", start});
  ASSERT_EQ(with.exit_status, 0) << with.err;
  EXPECT_THAT(with.err, HasSubstr("start from the given state"));
  const nlohmann::json summary =
      nlohmann::json::parse(test::ReadTextFile(tmp / "with/summary.json"));
  EXPECT_EQ(summary["estimates"].get<int>(), summary["frames"].get<int>());
  const auto e = test::RunAuvdock(
      {"evaluate", "--dataset", dataset, "--estimate", tmp / "with/trajectory.tum", "--json"});
  ASSERT_EQ(e.exit_status, 0) << e.err;
  // Dead reckoning on the DVL for 20 s from a start known to 0.1 m.
  EXPECT_LT(nlohmann::json::parse(e.out).at("pos_rmse_m").get<double>(), 0.3) << e.out;

  test::WriteTextFile(start,
                      "p_D: [0, 0, 0]\nrpy_deg: [0, 0, 0]\nposition_sigma_m: 0.1\n"
                      "tilt_sigma_deg: 0.5\nheading_sigma_deg: -1\n"
                      "velocity_sigma_mps: 0.05\n");
  const auto bad = test::RunAuvdock(
      {"run", "--dataset", dataset, "--out", tmp / "bad", "--quiet", "--start", start});
  EXPECT_EQ(bad.exit_status, 2);
  EXPECT_THAT(bad.err, HasSubstr("start.yaml"));
  EXPECT_THAT(bad.err, HasSubstr("heading_sigma_deg"));
}

// Divergence: a start given 20 m off with a sigma of 0.1 m makes the gate refuse every fix,
// which agree with each other; with no light in view the window is reset ("divergence", the
// frame's NO-GO says why) and starts again from the fixes, and ends where the truth does.
TEST(WithoutCamerasCli, AWindowThatRefusesEveryFixRestartsFromThem) {
  test::TempDir tmp;
  const std::string dataset = NavigatorsLog(tmp, 30.0, /*with_fixes=*/true);
  ASSERT_FALSE(::testing::Test::HasFailure());
  const std::string start = tmp / "start.yaml";
  WriteStart(start, "12.0, 1.07, -4.43", "0.0, 1.2884, 9.3639", "0.496, 0.026, 0.038");
  const auto r = test::RunAuvdock(
      {"run", "--dataset", dataset, "--out", tmp / "out", "--quiet", "--start", start});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("divergence: the gate refused"));
  const nlohmann::json summary =
      nlohmann::json::parse(test::ReadTextFile(tmp / "out/summary.json"));
  EXPECT_EQ(summary["divergences"].get<int>(), 1);
  EXPECT_EQ(summary["acoustic_starts"].get<int>(), 1);
  EXPECT_THAT(test::ReadTextFile(tmp / "out/decisions.csv"),
              HasSubstr("not initialised (divergence"));
  // The last estimate against the truth at its time.
  std::istringstream tum(test::ReadTextFile(tmp / "out/trajectory.tum"));
  std::string line, last;
  while (std::getline(tum, line)) {
    if (!line.empty() && line[0] != '#') last = line;
  }
  std::istringstream fields(last);
  double t_s = 0.0, x = 0.0, y = 0.0;
  fields >> t_s >> x >> y;
  std::istringstream truth(test::ReadTextFile(dataset + "/groundtruth/data.csv"));
  double best_dt = 1e9, truth_x = 0.0, truth_y = 0.0;
  while (std::getline(truth, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream row(line);
    double t_ns = 0.0, tx = 0.0, ty = 0.0;
    row >> t_ns >> tx >> ty;
    if (std::abs(t_ns * 1e-9 - t_s) < best_dt) {
      best_dt = std::abs(t_ns * 1e-9 - t_s);
      truth_x = tx;
      truth_y = ty;
    }
  }
  EXPECT_LT(best_dt, 0.01);
  EXPECT_LT(std::hypot(x - truth_x, y - truth_y), 0.3) << last;
}

// A DVL mounted turned 180 deg about z from what its T_B_S says, with a heading sensor: the
// acoustic start finds most fixes off the DVL's path under the measured heading and refuses to
// start, every frame NO-GO with that reason, instead of a start on the two fixes that agree.
TEST(WithoutCamerasCli, ADvlInTheWrongFrameIsNoStart) {
  test::TempDir tmp;
  const std::string dataset =
      NavigatorsLog(tmp, 30.0, /*with_fixes=*/true, "heading: {rate_hz: 10.0, sigma_deg: 2.0}\n");
  ASSERT_FALSE(::testing::Test::HasFailure());
  YAML::Node calibration = YAML::LoadFile(dataset + "/calibration.yaml");
  YAML::Node T = calibration["dvl"]["T_B_S"];
  for (const int k : {0, 1, 2, 4, 5, 6}) T[k] = -T[k].as<double>();  // R_z(180 deg) R
  YAML::Emitter out;
  out << calibration;
  test::WriteTextFile(dataset + "/calibration.yaml", out.c_str());
  const auto r = test::RunAuvdock({"run", "--dataset", dataset, "--out", tmp / "out", "--quiet"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr(": 0 estimates"));
  EXPECT_THAT(test::ReadTextFile(tmp / "out/decisions.csv"),
              HasSubstr("disagree with the DVL's path under the measured heading"));
}

}  // namespace
}  // namespace auvdock
