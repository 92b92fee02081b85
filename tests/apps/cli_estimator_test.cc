// End-to-end tests of `auvdock run` and `auvdock smooth` on a short simulated dataset: the files
// they write, that those files evaluate, and how bad input is handled (skipped, counted, never a
// NaN pose; a bad option file is one line and exit 2).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "auvdock/io/dataset.h"
#include "auvdock/io/decisions_csv.h"
#include "auvdock/io/rejections_csv.h"
#include "auvdock/io/pose_covariance_csv.h"
#include "auvdock/io/tum_io.h"
#include "tests/testing/run_command.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_scenarios.h"

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

namespace auvdock {
namespace {

class EstimatorCli : public ::testing::Test {
 protected:
  // 3 s of the default scenario (the stereo-only approach) at full resolution, once per suite.
  static void SetUpTestSuite() {
    tmp_ = new test::TempDir();
    dataset_ = *tmp_ / "ds";
    const std::string scenario = *tmp_ / "s.yaml";
    // DVL spikes on a fifth of the samples, so that a few fall in 3 s.
    test::WriteTextFile(scenario, "name: short\nduration_s: 3.0\ndock: " +
                                      test::SourcePath("data/docks/t_shape.yaml") +
                                      "\ndvl: {gross_error_probability: 0.2}\n");
    const auto r =
        test::RunAuvdock({"simulate", "--scenario", scenario, "--out", dataset_, "--quiet"});
    ASSERT_EQ(r.exit_status, 0) << r.err;
  }
  static void TearDownTestSuite() { delete tmp_; }

  static nlohmann::json Summary(const std::string& out) {
    return nlohmann::json::parse(test::ReadTextFile(out + "/summary.json"));
  }

  static test::TempDir* tmp_;
  static std::string dataset_;
};
test::TempDir* EstimatorCli::tmp_ = nullptr;
std::string EstimatorCli::dataset_;

void ExpectFinitePoses(const Trajectory& poses) {
  for (const StampedPose& pose : poses) {
    EXPECT_TRUE(pose.T_D_B.p.allFinite() && pose.T_D_B.q.coeffs().allFinite()) << pose.t_ns;
  }
}

TEST_F(EstimatorCli, RunAndSmoothWriteEveryFileAndTheFilesEvaluate) {
  for (const std::string command : {"run", "smooth"}) {
    const std::string out = *tmp_ / (command + "_out");
    const auto r = test::RunAuvdock({command, "--dataset", dataset_, "--out", out, "--quiet"});
    ASSERT_EQ(r.exit_status, 0) << command << ": " << r.err;

    const Trajectory poses = ReadTumTrajectory(out + "/trajectory.tum");
    EXPECT_GE(poses.size(), 25u) << command;  // of 31 frames; the first waits for a pose
    ExpectFinitePoses(poses);
    const std::vector<StampedPoseCovariance> covariances =
        ReadPoseCovarianceCsv(out + "/covariance.csv");  // validates symmetry and definiteness
    EXPECT_EQ(covariances.size(), poses.size()) << command;
    const std::vector<StampedDecision> decisions = ReadDecisionsCsv(out + "/decisions.csv");
    EXPECT_EQ(decisions.size(), 31u) << command;  // one per frame, with or without an estimate

    const nlohmann::json summary = Summary(out);
    EXPECT_EQ(summary.at("frames").get<int>(), 31) << command;
    EXPECT_DOUBLE_EQ(summary.at("data_duration_s").get<double>(), 3.0);
    for (const char* key : {"decode", "frontend", "backend", "total"}) {
      EXPECT_GE(summary.at("timing_s").at(key).get<double>(), 0.0) << command << " " << key;
    }
    EXPECT_EQ(summary.at("resets").get<int>(), 0) << command;
    // 31 depth samples at 10 Hz; the first ones come before the first state.
    EXPECT_GE(summary.at("depth_samples").at("used").get<int>(), 20) << command;
    // 16 DVL samples at 5 Hz, of which `run` leaves out the first ~1.5 s until the window can
    // test them (the DVL's admission); every spike the simulator injected is in rejections.csv.
    const nlohmann::json& dvl = summary.at("dvl_samples");
    EXPECT_GE(dvl.at("used").get<int>(), 5) << command;
    EXPECT_GE(dvl.at("used").get<int>() + dvl.value("not_admitted", 0), 10) << command;
    const std::vector<Rejection> rejections = ReadRejectionsCsv(out + "/rejections.csv");
    EXPECT_EQ(summary.at("rejections").get<int>(), static_cast<int>(rejections.size()));
    int spikes = 0;
    for (const FaultRecord& fault : LoadDataset(dataset_).faults) {
      if (fault.sensor != "dvl0" || fault.kind != "gross_error") continue;
      ++spikes;
      EXPECT_TRUE(std::any_of(rejections.begin(), rejections.end(), [&](const Rejection& r) {
        return r.sensor == "dvl0" && r.t_ns == fault.t_ns && r.statistic > 16.27;
      })) << command << ": the DVL spike at " << fault.t_ns << " ns is not rejected";
    }
    EXPECT_GE(spikes, 1);

    const auto e = test::RunAuvdock({"evaluate", "--dataset", dataset_, "--estimate",
                                     out + "/trajectory.tum", "--covariance",
                                     out + "/covariance.csv", "--decisions",
                                     out + "/decisions.csv", "--json"});
    ASSERT_EQ(e.exit_status, 0) << e.err;
    const nlohmann::json report = nlohmann::json::parse(e.out);
    // Stereo at 8-10 m over a 0.25 m baseline: a sanity bound, not the accuracy target.
    EXPECT_LT(report.at("pos_rmse_m").get<double>(), 0.3) << command;
    EXPECT_EQ(report.at("nees_n").get<int>(), static_cast<int>(covariances.size()));
    EXPECT_EQ(report.at("decisions").at("n_go_unsafe").get<int>(), 0) << command;
  }
}

// A corrupt image, a missing one, an IMU row with NaN and a repeated IMU timestamp: the run goes
// on, skips them, says so in summary.json and its log, and writes no NaN pose.
TEST_F(EstimatorCli, RunSkipsBadMeasurementsAndCountsThem) {
  const std::string ds = *tmp_ / "bad_ds";
  fs::copy(dataset_, ds, fs::copy_options::recursive);
  std::vector<fs::path> images;
  for (const auto& entry : fs::directory_iterator(ds + "/cam0/data"))
    images.push_back(entry.path());
  std::sort(images.begin(), images.end());
  ASSERT_GT(images.size(), 20u);
  test::WriteTextFile(images[15].string(), "not a png");
  fs::remove(images[25]);  // listed in data.csv, gone from data/

  const std::string imu_path = ds + "/imu0/data.csv";
  std::vector<std::string> lines;
  {
    std::ifstream in(imu_path);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
  }
  ASSERT_GT(lines.size(), 300u);
  const std::string t_200 = lines[200].substr(0, lines[200].find(','));
  lines[200] = t_200 + ",nan,0,0,0,0,-9.81";
  lines.insert(lines.begin() + 301, lines[300]);  // the same timestamp again
  {
    std::ofstream out(imu_path);
    for (const std::string& line : lines) out << line << "\n";
  }

  const std::string out = *tmp_ / "bad_out";
  const auto r = test::RunAuvdock({"run", "--dataset", ds, "--out", out, "--quiet"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_THAT(r.err, AllOf(HasSubstr("image skipped"), HasSubstr("imu0/data.csv"),
                           HasSubstr(images[25].filename().string() + ": missing")));
  const nlohmann::json summary = Summary(out);
  EXPECT_EQ(summary.at("unreadable_images").get<int>(), 2);
  EXPECT_EQ(summary.at("skipped").at("dataset_rows").get<int>(), 2);
  const Trajectory poses = ReadTumTrajectory(out + "/trajectory.tum");
  EXPECT_GE(poses.size(), 25u);
  ExpectFinitePoses(poses);
}

// Cameras not synchronised with each other: the mono camera's time stamps moved 37 ms later.
// Each mono image joins the stereo pair's frame before it (one state per frame, as before); with
// --sync-tolerance-ms 0 every image time is a frame of its own.
TEST_F(EstimatorCli, UnsynchronisedCamerasShareOneStatePerFrame) {
  const std::string ds = *tmp_ / "unsync_ds";
  fs::copy(dataset_, ds, fs::copy_options::recursive);
  const std::string csv = ds + "/cam2/data.csv";
  std::vector<std::string> lines;
  {
    std::ifstream in(csv);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
  }
  ASSERT_EQ(lines.size(), 32u);  // header + 31 images
  for (size_t i = 1; i < lines.size(); ++i) {
    const size_t comma = lines[i].find(',');
    lines[i] = std::to_string(std::stoll(lines[i].substr(0, comma)) + 37000000) +
               lines[i].substr(comma);
  }
  {
    std::ofstream out(csv);
    for (const std::string& line : lines) out << line << "\n";
  }
  for (const auto& [tolerance, frames] : {std::pair<std::string, int>{"", 31}, {"0", 62}}) {
    const std::string out = *tmp_ / ("unsync_out" + tolerance);
    std::vector<std::string> args = {"run", "--dataset", ds, "--out", out, "--quiet"};
    if (!tolerance.empty()) args.insert(args.end(), {"--sync-tolerance-ms", tolerance});
    const auto r = test::RunAuvdock(args);
    ASSERT_EQ(r.exit_status, 0) << r.err;
    EXPECT_EQ(Summary(out).at("frames").get<int>(), frames) << tolerance;
    EXPECT_EQ(ReadDecisionsCsv(out + "/decisions.csv").size(), static_cast<size_t>(frames));
    const Trajectory poses = ReadTumTrajectory(out + "/trajectory.tum");
    EXPECT_GE(poses.size(), 25u);
    ExpectFinitePoses(poses);
  }
  const auto bad = test::RunAuvdock(
      {"run", "--dataset", ds, "--out", *tmp_ / "unsync_bad", "--sync-tolerance-ms", "nan"});
  EXPECT_EQ(bad.exit_status, 2);
  EXPECT_THAT(bad.err, HasSubstr("--sync-tolerance-ms"));
}

TEST_F(EstimatorCli, BadOptionsFileIsOneLineExitTwoAndWritesNothing) {
  const std::string config = *tmp_ / "bad.yaml";
  test::WriteTextFile(config, "estimator:\n  window_size: 1\n  no_such_key: 3\n");
  const std::string out = *tmp_ / "never";
  const auto r = test::RunAuvdock({"run", "--dataset", dataset_, "--out", out, "--config", config});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_THAT(r.err, HasSubstr("bad.yaml"));
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out));

  const auto missing = test::RunAuvdock({"smooth", "--dataset", *tmp_ / "nope", "--out", out});
  EXPECT_EQ(missing.exit_status, 2);
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace auvdock
