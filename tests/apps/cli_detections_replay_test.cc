// End-to-end: `simulate --detections-only` writes detections.csv instead of images, and `run` /
// `smooth --detections` replay it through the estimator; `frontend`'s own detections.csv
// replays too; a detections file that does not fit the calibration or the dock is one line,
// exit 2, naming the file and line; a `run` stopped by SIGINT or SIGTERM keeps, whole, every
// row it wrote before the stop.
#include <signal.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "auvdock/io/decisions_csv.h"
#include "auvdock/io/detections_csv.h"
#include "auvdock/io/pose_covariance_csv.h"
#include "auvdock/io/sensor_csv.h"
#include "auvdock/io/tum_io.h"
#include "tests/testing/run_command.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_scenarios.h"

namespace fs = std::filesystem;
using ::testing::HasSubstr;

namespace auvdock {
namespace {

class DetectionsReplayCli : public ::testing::Test {
 protected:
  // 12 s of the default scenario from its start: the stereo approach and the first mono frames.
  static void SetUpTestSuite() {
    tmp_ = new test::TempDir();
    dataset_ = *tmp_ / "ds";
    const std::string scenario = *tmp_ / "s.yaml";
    test::WriteTextFile(scenario, "name: short\nduration_s: 12.0\ndock: " +
                                      test::SourcePath("data/docks/t_shape.yaml") + "\n");
    const auto r = test::RunAuvdock(
        {"simulate", "--scenario", scenario, "--out", dataset_, "--detections-only", "--quiet"});
    ASSERT_EQ(r.exit_status, 0) << r.err;
  }
  static void TearDownTestSuite() { delete tmp_; }
  static test::TempDir* tmp_;
  static std::string dataset_;
};
test::TempDir* DetectionsReplayCli::tmp_ = nullptr;
std::string DetectionsReplayCli::dataset_;

TEST_F(DetectionsReplayCli, SimulateWritesDetectionsAndNoImages) {
  for (const char* camera : {"cam0", "cam1", "cam2"}) {
    const fs::path images = fs::path(dataset_) / camera / "data";
    EXPECT_TRUE(!fs::exists(images) || fs::is_empty(images)) << camera;
  }
  const std::vector<ImageDetections> images = ReadDetectionsCsv(dataset_ + "/detections.csv");
  // 121 frames x 3 cameras, each image listed (with detections or as "saw nothing").
  EXPECT_EQ(images.size(), 3u * 121u);
  int identified = 0;
  for (const ImageDetections& image : images) {
    for (int id : image.light_ids) identified += id >= 0 ? 1 : 0;
  }
  EXPECT_GT(identified, 1000);
  EXPECT_THAT(test::ReadTextFile(dataset_ + "/groundtruth/faults.csv"), HasSubstr("missed_light"));
}

TEST_F(DetectionsReplayCli, RunAndSmoothReplayTheDetections) {
  for (const std::string command : {"run", "smooth"}) {
    const std::string out = *tmp_ / (command + "_out");
    const auto r = test::RunAuvdock({command, "--dataset", dataset_, "--detections",
                                     dataset_ + "/detections.csv", "--out", out, "--quiet"});
    ASSERT_EQ(r.exit_status, 0) << command << ": " << r.err;
    EXPECT_GE(ReadTumTrajectory(out + "/trajectory.tum").size(), 110u) << command;
    const auto e =
        test::RunAuvdock({"evaluate", "--dataset", dataset_, "--estimate", out + "/trajectory.tum",
                          "--covariance", out + "/covariance.csv", "--json"});
    ASSERT_EQ(e.exit_status, 0) << e.err;
    const nlohmann::json report = nlohmann::json::parse(e.out);
    // Stereo at 4-10 m: a sanity bound (the image path's own test uses 0.3 m on 3 s).
    EXPECT_LT(report.at("pos_rmse_m").get<double>(), 0.1) << command;
  }
}

// `crlb` bounds every frame's pose from the same detections; `evaluate --bound` sets the
// smoother's errors beside it (same order of magnitude: the smoother is nearly efficient on
// synthetic detections, whose faults the gates take out). Without ground truth, or with a folder
// for --out, one line and exit 2, and no file left behind.
TEST_F(DetectionsReplayCli, TheBoundOfEveryPoseBesideTheSmoothersErrors) {
  const std::string bound = *tmp_ / "crlb.csv";
  const auto r = test::RunAuvdock({"crlb", "--dataset", dataset_, "--detections",
                                   dataset_ + "/detections.csv", "--out", bound, "--quiet"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("121 poses with a bound"));
  const std::vector<StampedPoseCovariance> poses = ReadPoseCovarianceCsv(bound);
  ASSERT_EQ(poses.size(), 121u);
  for (const StampedPoseCovariance& p : poses) {
    const double position = p.covariance.topLeftCorner<3, 3>().trace();
    EXPECT_GT(position, 0.0);
    EXPECT_LT(position, 0.5 * 0.5 * 3.0);  // within the first state's prior
  }
  const std::string smooth = *tmp_ / "crlb_smooth";
  ASSERT_EQ(test::RunAuvdock({"smooth", "--dataset", dataset_, "--detections",
                              dataset_ + "/detections.csv", "--out", smooth, "--quiet"})
                .exit_status,
            0);
  const auto e = test::RunAuvdock({"evaluate", "--dataset", dataset_, "--estimate",
                                   smooth + "/trajectory.tum", "--bound", bound, "--json"});
  ASSERT_EQ(e.exit_status, 0) << e.err;
  const nlohmann::json report = nlohmann::json::parse(e.out);
  EXPECT_GE(report.at("bound_n").get<int>(), 110);
  const double ratio =
      report.at("pos_rmse_at_bound_m").get<double>() / report.at("bound_pos_rms_m").get<double>();
  // 0.24 since the DVL's bias is a state (its prior widens the bound; the simulated DVL has
  // none, so the smoother does better than the configured model says).
  EXPECT_GT(ratio, 0.15);
  EXPECT_LT(ratio, 3.0);

  const fs::path no_truth = *tmp_ / "no_truth";
  fs::copy(dataset_, no_truth, fs::copy_options::recursive);
  fs::remove(no_truth / "groundtruth" / "data.csv");
  const std::string none = *tmp_ / "crlb_none.csv";
  for (const auto& [dataset, out] : std::vector<std::pair<std::string, std::string>>{
           {no_truth.string(), none}, {dataset_, tmp_->path()}}) {
    const auto bad = test::RunAuvdock({"crlb", "--dataset", dataset, "--detections",
                                       dataset_ + "/detections.csv", "--out", out, "--quiet"});
    EXPECT_EQ(bad.exit_status, 2) << bad.err;
    EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
  }
  EXPECT_FALSE(fs::exists(none));
  EXPECT_FALSE(fs::exists(none + ".partial"));
}

TEST_F(DetectionsReplayCli, ADatasetWithoutImagesPointsToTheDetections) {
  const auto r = test::RunAuvdock({"run", "--dataset", dataset_, "--out", *tmp_ / "no_images"});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_THAT(r.err, HasSubstr("--detections"));
}

// A dataset folder without its dock.yaml (a real log, a EuRoC sequence): the run says how to give
// one; --dock gives it from anywhere, and a malformed one is named.
TEST_F(DetectionsReplayCli, TheDockComesFromDockWhenTheDatasetHasNone) {
  const fs::path bare = *tmp_ / "bare";
  fs::copy(dataset_, bare, fs::copy_options::recursive);
  fs::remove(bare / "dock.yaml");
  const std::vector<std::string> run = {
      "run", "--dataset", bare.string(), "--detections", dataset_ + "/detections.csv", "--quiet"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = run;
    args.insert(args.end(), extra.begin(), extra.end());
    return test::RunAuvdock(args);
  };
  const auto without = with({"--out", *tmp_ / "bare_out"});
  EXPECT_EQ(without.exit_status, 2);
  EXPECT_THAT(without.err, HasSubstr("--dock"));
  EXPECT_EQ(std::count(without.err.begin(), without.err.end(), '\n'), 1) << without.err;

  const auto given = with({"--dock", dataset_ + "/dock.yaml", "--out", *tmp_ / "bare_docked"});
  ASSERT_EQ(given.exit_status, 0) << given.err;
  EXPECT_GE(ReadTumTrajectory(*tmp_ / "bare_docked/trajectory.tum").size(), 110u);

  const std::string bad = *tmp_ / "bad_dock.yaml";
  test::WriteTextFile(bad, "lights: [[0, 0\n");
  const auto malformed = with({"--dock", bad, "--out", *tmp_ / "bare_bad"});
  EXPECT_EQ(malformed.exit_status, 2);
  EXPECT_THAT(malformed.err, HasSubstr("bad_dock.yaml"));
}

// --euroc-csv: the state in EuRoC's ground-truth columns, read back by the ground-truth reader,
// pose for pose the trajectory.tum of the same run.
TEST_F(DetectionsReplayCli, TheEstimateAlsoInEurocColumns) {
  const std::string out = *tmp_ / "euroc_out";
  const auto r =
      test::RunAuvdock({"run", "--dataset", dataset_, "--detections", dataset_ + "/detections.csv",
                        "--euroc-csv", "--out", out, "--quiet"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::vector<GroundTruthState> states = ReadGroundTruthCsv(out + "/estimate.csv");
  const Trajectory tum = ReadTumTrajectory(out + "/trajectory.tum");
  ASSERT_EQ(states.size(), tum.size());
  ASSERT_GE(states.size(), 110u);
  for (size_t i = 0; i < states.size(); ++i) {
    EXPECT_NEAR(states[i].T_D_B.p.x(), tum[i].T_D_B.p.x(), 1e-9);
    EXPECT_NEAR(states[i].T_D_B.p.z(), tum[i].T_D_B.p.z(), 1e-9);
    EXPECT_NEAR(std::abs(states[i].T_D_B.q.dot(tum[i].T_D_B.q)), 1.0, 1e-12);
    EXPECT_LT(states[i].v_D.norm(), 3.0);  // a docking approach, not a blow-up
  }
  EXPECT_FALSE(fs::exists(*tmp_ / "run_out/estimate.csv")) << "only with --euroc-csv";
  // As evo_traj euroc reads it (evo/tools/file_interface.py, read_euroc_csv_trajectory): '#'
  // lines skipped, every other line exactly 17 comma-separated numbers, the time in ns.
  std::ifstream in(out + "/estimate.csv");
  size_t rows = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind('#', 0) == 0) continue;
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 16) << line;
    EXPECT_NE(line.back(), ',') << line;
    EXPECT_EQ(line.substr(0, line.find(',')), std::to_string(states[rows].t_ns));
    ++rows;
  }
  EXPECT_EQ(rows, states.size());
}

// Complete rows (ended by a newline; a row being written is not one yet), comments not counted.
int CountRows(const std::string& path) {
  const std::string text = test::ReadTextFile(path);
  int rows = 0;
  for (size_t start = 0, end; (end = text.find('\n', start)) != std::string::npos;
       start = end + 1) {
    rows += end > start && text[start] != '#';
  }
  return rows;
}

TEST_F(DetectionsReplayCli, AnInterruptedRunKeepsEveryRowItWrote) {
  // The whole default run (401 frames): the run stops a few frames after the signal, and a fast
  // back-end (~1 ms a frame) must not finish the log before a loaded machine delivers it.
  const std::string long_dataset = *tmp_ / "ds_long";
  const std::string scenario = *tmp_ / "long.yaml";
  test::WriteTextFile(scenario, "name: long\nduration_s: 40.0\ndock: " +
                                    test::SourcePath("data/docks/t_shape.yaml") + "\n");
  ASSERT_EQ(test::RunAuvdock({"simulate", "--scenario", scenario, "--out", long_dataset,
                              "--detections-only", "--quiet"})
                .exit_status,
            0);
  for (const int signal : {SIGINT, SIGTERM}) {
    const std::string out = *tmp_ / ("stopped_" + std::to_string(signal));
    // Stop once 20 poses are out (flushed per frame).
    const auto r = test::RunAuvdockAndSignalWhen(
        {"run", "--dataset", long_dataset, "--detections", long_dataset + "/detections.csv",
         "--out", out, "--quiet"},
        [&] { return CountRows(out + "/trajectory.tum") >= 20; }, signal);
    ASSERT_EQ(r.exit_status, 130) << "signal " << signal << ": " << r.err;
    EXPECT_THAT(r.err, HasSubstr("interrupted"));
    const Trajectory poses = ReadTumTrajectory(out + "/trajectory.tum");
    EXPECT_GE(poses.size(), 20u);
    EXPECT_LT(poses.size(), 380u) << "the run was not stopped early";
    for (const StampedPose& pose : poses) {
      EXPECT_TRUE(pose.T_D_B.p.allFinite() && pose.T_D_B.q.coeffs().allFinite()) << pose.t_ns;
    }
    // The other per-frame files parse to the last row and agree with the trajectory.
    const std::vector<StampedPoseCovariance> covariances =
        ReadPoseCovarianceCsv(out + "/covariance.csv");
    const std::vector<StampedDecision> decisions = ReadDecisionsCsv(out + "/decisions.csv");
    EXPECT_GE(covariances.size() + 2, poses.size());
    EXPECT_LE(covariances.size(), poses.size());
    std::set<int64_t> decided;
    for (const StampedDecision& d : decisions) decided.insert(d.t_ns);
    for (const StampedPose& pose : poses) {  // TUM times are seconds: within a microsecond
      const auto next = decided.lower_bound(pose.t_ns - 1000);
      EXPECT_TRUE(next != decided.end() && *next <= pose.t_ns + 1000) << pose.t_ns;
    }
    const nlohmann::json summary = nlohmann::json::parse(test::ReadTextFile(out + "/summary.json"));
    EXPECT_TRUE(summary.at("interrupted").get<bool>());
  }
}

TEST_F(DetectionsReplayCli, DetectionsThatDoNotFitAreOneLineExitTwo) {
  const std::string header =
      "#timestamp_ns,camera,light_id,u,v,radius,score\n"
      "1700000000000000000,cam0,1,100,100,2,1\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"1700000000100000000,cam7,1,100,100,2,1\n", "camera 'cam7' is not in the calibration"},
      {"1700000000100000000,cam0,42,100,100,2,1\n", "light 42 is not a light of the dock"},
      {"1700000000100000000,cam0,1,100,x,2,1\n", "column 'v'"},
  };
  int k = 0;
  for (const auto& [row, expected] : cases) {
    const std::string file = *tmp_ / ("bad" + std::to_string(k) + ".csv");
    const std::string out = *tmp_ / ("bad_out" + std::to_string(k++));
    test::WriteTextFile(file, header + row);
    const auto r = test::RunAuvdock(
        {"run", "--dataset", dataset_, "--detections", file, "--out", out, "--quiet"});
    EXPECT_EQ(r.exit_status, 2) << row;
    EXPECT_THAT(r.err, HasSubstr(file + ": line 3")) << r.err;
    EXPECT_THAT(r.err, HasSubstr(expected)) << r.err;
    EXPECT_FALSE(fs::exists(out + "/trajectory.tum")) << row;
  }
}

TEST(FrontendDetectionsReplayCli, FrontendDetectionsReplayThroughRun) {
  test::TempDir tmp;
  const std::string scenario = tmp / "s.yaml";
  test::WriteTextFile(scenario, "name: short\nduration_s: 2.0\ndock: " +
                                    test::SourcePath("data/docks/t_shape.yaml") + "\n");
  const std::string ds = tmp / "ds", fe = tmp / "fe", out = tmp / "run";
  ASSERT_EQ(
      test::RunAuvdock({"simulate", "--scenario", scenario, "--out", ds, "--quiet"}).exit_status,
      0);
  ASSERT_EQ(test::RunAuvdock({"frontend", "--dataset", ds, "--out", fe, "--quiet"}).exit_status, 0);
  // Every image of the 21 frames is in the file, including those that saw nothing.
  EXPECT_EQ(ReadDetectionsCsv(fe + "/detections.csv").size(), 3u * 21u);
  const auto r = test::RunAuvdock(
      {"run", "--dataset", ds, "--detections", fe + "/detections.csv", "--out", out, "--quiet"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_GE(ReadTumTrajectory(out + "/trajectory.tum").size(), 15u);
}

}  // namespace
}  // namespace auvdock
