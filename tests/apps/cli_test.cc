// End-to-end tests of the auvdock command line: simulate -> evaluate, and bad input
// (one line on stderr, exit status 2, nothing half-written left behind).
#include <csignal>
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "auvdock/io/tum_io.h"
#include "tests/testing/run_command.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_scenarios.h"

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

namespace auvdock {
namespace {

int CountLines(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

// A short, small-image copy of the default scenario (the dock by absolute path).
std::string WriteShortScenario(const test::TempDir& tmp, double duration_s,
                               const std::string& extra = "") {
  const std::string path = tmp / "short.yaml";
  test::WriteTextFile(path, "name: short\nduration_s: " + std::to_string(duration_s) +
                                "\ndock: " + test::SourcePath("data/docks/t_shape.yaml") +
                                "\ncameras: {resolution: [160, 128]}\n" + extra);
  return path;
}

class CliTest : public ::testing::Test {
 protected:
  // Simulates once for the whole suite.
  static void SetUpTestSuite() {
    tmp_ = new test::TempDir();
    dataset_ = *tmp_ / "ds";
    const auto r = test::RunAuvdock(
        {"simulate", "--scenario", WriteShortScenario(*tmp_, 3.0), "--out", dataset_, "--quiet"});
    ASSERT_EQ(r.exit_status, 0) << r.err;
  }
  static void TearDownTestSuite() { delete tmp_; }

  static test::TempDir* tmp_;
  static std::string dataset_;
};
test::TempDir* CliTest::tmp_ = nullptr;
std::string CliTest::dataset_;

TEST_F(CliTest, SimulateWritesTheDatasetLayout) {
  for (const char* f : {"calibration.yaml", "dock.yaml", "cam0/data.csv", "cam1/data.csv",
                        "cam2/data.csv", "imu0/data.csv", "depth0/data.csv", "dvl0/data.csv",
                        "usbl0/data.csv", "groundtruth/data.csv", "groundtruth/visibility.csv",
                        "groundtruth/faults.csv", "groundtruth.tum"}) {
    EXPECT_TRUE(fs::exists(dataset_ + "/" + f)) << f;
  }
  EXPECT_FALSE(fs::exists(dataset_ + ".partial-" + std::to_string(0)));
}

TEST_F(CliTest, EvaluateTruthAgainstItselfIsZero) {
  const auto r = test::RunAuvdock(
      {"evaluate", "--dataset", dataset_, "--estimate", dataset_ + "/groundtruth.tum", "--json"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("n_poses").get<int>(), 601);
  EXPECT_LT(j.at("pos_rmse_m").get<double>(), 1e-9);
  EXPECT_LT(j.at("att_rmse_rad").get<double>(), 1e-7);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(j.at("pos_max_abs_m")[i].get<double>(), 1e-9);
    EXPECT_LT(j.at("att_max_abs_rad")[i].get<double>(), 1e-7);
  }
}

TEST_F(CliTest, EvaluateReturnsAKnownOffset) {
  Trajectory estimate = ReadTumTrajectory(dataset_ + "/groundtruth.tum");
  const Eigen::Vector3d offset(0.03, -0.02, 0.01);
  for (auto& pose : estimate) pose.T_D_B.p += offset;
  const std::string path = *tmp_ / "shifted.tum";
  WriteTumTrajectory(path, estimate);
  const auto r =
      test::RunAuvdock({"evaluate", "--dataset", dataset_, "--estimate", path, "--json"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j.at("pos_rmse_m").get<double>(), offset.norm(), 1e-9);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(j.at("pos_max_abs_m")[i].get<double>(), std::abs(offset[i]), 1e-9);
    EXPECT_NEAR(j.at("pos_mean_m")[i].get<double>(), offset[i], 1e-9);
  }
  // The stages reported are those of the visibility file.
  EXPECT_TRUE(j.at("stages").contains("stereo_only"));
}

TEST_F(CliTest, EvaluatePrintsATableByDefault) {
  const auto r = test::RunAuvdock(
      {"evaluate", "--dataset", dataset_, "--estimate", dataset_ + "/groundtruth.tum"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("stereo_only"));
}

// --plots: the five PNGs (scripts/plot_run.py, /usr/bin/python3 with matplotlib), with a
// covariance for the first poses (the +-3 sigma band and the NEES) and no decisions.
TEST_F(CliTest, EvaluateWritesThePlots) {
  std::ifstream truth(dataset_ + "/groundtruth/data.csv");
  std::string line;
  std::getline(truth, line);  // header
  std::string covariance = "#timestamp [ns],c00..c55\n";
  for (int k = 0; k < 20 && std::getline(truth, line); ++k) {
    covariance += line.substr(0, line.find(','));
    for (int i = 0; i < 36; ++i) covariance += i % 7 == 0 ? ",1e-4" : ",0";
    covariance += "\n";
  }
  const std::string covariance_path = *tmp_ / "covariance.csv";
  test::WriteTextFile(covariance_path, covariance);
  const std::string plots = *tmp_ / "plots";
  const auto r = test::RunAuvdock({"evaluate", "--dataset", dataset_, "--estimate",
                                   dataset_ + "/groundtruth.tum", "--covariance", covariance_path,
                                   "--plots", plots});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("plots: " + plots));
  for (const char* name :
       {"trajectory.png", "errors.png", "stages.png", "nees.png", "go_no_go.png"}) {
    std::ifstream png(plots + "/" + name, std::ios::binary);
    char signature[4] = {};
    png.read(signature, 4);
    EXPECT_EQ(std::string(signature + 1, 3), "PNG") << name;
    EXPECT_GT(fs::file_size(plots + "/" + name), 10000u) << name;
  }
}

TEST_F(CliTest, PlotsThatCannotBeWrittenAreOneLineAndLeaveNothing) {
  const std::string blocker = *tmp_ / "not_a_folder";
  test::WriteTextFile(blocker, "x");
  const auto r = test::RunAuvdock({"evaluate", "--dataset", dataset_, "--estimate",
                                   dataset_ + "/groundtruth.tum", "--plots", blocker});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr(blocker));
  for (const auto& entry : fs::directory_iterator(tmp_->path())) {
    EXPECT_EQ(entry.path().filename().string().rfind(".plots-", 0), std::string::npos)
        << entry.path();
  }
}

TEST_F(CliTest, MalformedEstimateIsOneLineAndExitTwo) {
  const std::string path = *tmp_ / "bad.tum";
  test::WriteTextFile(path, "1700000000.0 0 0 0 0 0 0 1\n1700000000.1 0 0 zero 0 0 0 1\n");
  const auto r = test::RunAuvdock({"evaluate", "--dataset", dataset_, "--estimate", path});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_THAT(r.err, AllOf(HasSubstr(path), HasSubstr("line 2")));
}

// A typo is named, with the closest valid word, before anything it leaves missing.
TEST(Cli, UnknownWordsNameThemselvesAndTheClosestValidOne) {
  const auto sub = test::RunAuvdock({"rnu", "--dataset", "x"});
  EXPECT_EQ(sub.exit_status, 2);
  EXPECT_EQ(CountLines(sub.err), 1) << sub.err;
  EXPECT_THAT(sub.err, AllOf(HasSubstr("unknown subcommand 'rnu'"), HasSubstr("'run'?")));
  const auto option = test::RunAuvdock({"run", "--datset", "x"});
  EXPECT_EQ(option.exit_status, 2);
  EXPECT_EQ(CountLines(option.err), 1) << option.err;
  EXPECT_THAT(option.err,
              AllOf(HasSubstr("unknown option '--datset' of 'run'"), HasSubstr("'--dataset'?")));
  const auto with_value = test::RunAuvdock({"evaluate", "--plot=out", "--dataset", "x"});
  EXPECT_THAT(with_value.err, AllOf(HasSubstr("'--plot'"), HasSubstr("'--plots'?")));
  const auto far = test::RunAuvdock({"simulate", "--xyzzy"});
  EXPECT_THAT(far.err, AllOf(HasSubstr("'--xyzzy'"), HasSubstr("simulate --help")));
  // Known words pass to the parser: its own message for what is missing.
  EXPECT_THAT(test::RunAuvdock({"run"}).err, HasSubstr("--dataset"));
}

// Each subcommand's help says what it needs, what it writes and how to call it; where it
// mentions the shipped scenarios or options, their folder as this binary finds it (the build
// tree's share/auvdock links to data/), which exists.
TEST(Cli, EachSubcommandsHelpSaysWhatItNeedsAndWrites) {
  for (const char* sub :
       {"simulate", "run", "smooth", "crlb", "frontend", "evaluate", "pnp", "detect", "demo"}) {
    const auto r = test::RunAuvdock({sub, "--help"});
    EXPECT_EQ(r.exit_status, 0) << sub;
    EXPECT_THAT(r.out,
                AllOf(HasSubstr("Needs:"), HasSubstr("Example: auvdock " + std::string(sub))))
        << sub;
  }
  const auto run = test::RunAuvdock({"run", "--help"});
  EXPECT_THAT(run.out, AllOf(HasSubstr("--dock"), HasSubstr("trajectory.tum"),
                             HasSubstr("covariance.csv"), HasSubstr("decisions.csv")));
  const auto simulate = test::RunAuvdock({"simulate", "--help"});
  const std::string marker = "Shipped scenarios: ";
  const size_t at = simulate.out.find(marker);
  ASSERT_NE(at, std::string::npos) << simulate.out;
  const std::string folder = simulate.out.substr(
      at + marker.size(), simulate.out.find(' ', at + marker.size()) - at - marker.size());
  EXPECT_TRUE(fs::exists(fs::path(folder) / "default.yaml")) << folder;
  EXPECT_THAT(simulate.out, HasSubstr("randomized.yaml"));
}

// Values are checked by the parser: one line naming the option and what it takes, exit 2.
TEST(Cli, OptionValuesAreCheckedByTheParser) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"frontend", "--dataset", "x", "--out", "y", "--matcher", "nearest"}, "--matcher"},
      {{"run", "--dataset", "x", "--out", "y", "--detector", "sift"}, "--detector"},
      {{"pnp", "--calib", "x", "--points", "y", "--pixel-sigma", "-1"},
       "positive number of pixels"},
      {{"run", "--dataset", "x", "--out", "y", "--sync-tolerance-ms", "-2"}, "non-negative"},
      {{"detect", "--images", "x", "--calib", "y", "--dock", "z", "--out", "w", "--colour", "pink"},
       "--colour"},
  };
  for (const auto& [args, expected] : cases) {
    const auto r = test::RunAuvdock(args);
    EXPECT_EQ(r.exit_status, 2) << args[0];
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
    EXPECT_THAT(r.err, HasSubstr(expected));
    EXPECT_THAT(r.err, Not(HasSubstr("not a dataset folder"))) << "checked before any work";
  }
}

// The demo on 3 s of the default scenario: the three estimators side by side, every step's
// files kept, and a demo that cannot write where it is told says so in one line.
TEST(Cli, DemoComparesTheThreeEstimators) {
  test::TempDir tmp;
  const std::string scenario = tmp / "s.yaml";
  test::WriteTextFile(scenario, "name: short\nduration_s: 3.0\ndock: " +
                                    test::SourcePath("data/docks/t_shape.yaml") + "\n");
  const std::string out = tmp / "demo";
  const auto r = test::RunAuvdock({"demo", "--scenario", scenario, "--out", out});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_THAT(r.out, AllOf(HasSubstr("frontend"), HasSubstr("run"), HasSubstr("smooth"),
                           HasSubstr("all: position RMSE [mm]"), HasSubstr("mean NEES"),
                           HasSubstr("Cramer-Rao bound RMS")));
  for (const char* file : {"dataset/calibration.yaml", "frontend/per_frame.tum",
                           "run/trajectory.tum", "smooth/covariance.csv", "crlb.csv",
                           "evaluation.json", "demo.log"}) {
    EXPECT_TRUE(fs::exists(fs::path(out) / file)) << file;
  }
  const auto record = nlohmann::json::parse(test::ReadTextFile(out + "/evaluation.json"));
  EXPECT_LT(record.at("run").at("evaluation").at("pos_rmse_m").get<double>(), 0.1);
  EXPECT_GT(record.at("smooth").at("evaluation").at("nees_mean").get<double>(), 0.0);
  EXPECT_GT(record.at("smooth").at("evaluation").at("bound_pos_rms_m").get<double>(), 0.0);

  const auto again = test::RunAuvdock({"demo", "--scenario", scenario, "--out", out});
  EXPECT_EQ(again.exit_status, 2);
  EXPECT_EQ(CountLines(again.err), 1) << again.err;
  EXPECT_THAT(again.err, HasSubstr("not empty"));
}

TEST(Cli, UsageErrorsExitTwo) {
  EXPECT_EQ(test::RunAuvdock({}).exit_status, 2);
  EXPECT_EQ(test::RunAuvdock({"frobnicate"}).exit_status, 2);
  const auto r = test::RunAuvdock({"simulate", "--out", "/tmp/x"});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_EQ(test::RunAuvdock({"--help"}).exit_status, 0);
}

TEST(Cli, BadScenarioNamesFileAndKeyAndWritesNothing) {
  test::TempDir tmp;
  const std::string scenario = WriteShortScenario(tmp, 1.0, "imu: {rate_hz: -200}\n");
  const std::string out = tmp / "out";
  const auto r = test::RunAuvdock({"simulate", "--scenario", scenario, "--out", out});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_THAT(r.err, AllOf(HasSubstr(scenario), HasSubstr("imu.rate_hz")));
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(std::distance(fs::directory_iterator(tmp.path()), fs::directory_iterator()), 1);
}

TEST(Cli, NonEmptyOutputFolderIsRefusedAndLeftAlone) {
  test::TempDir tmp;
  const std::string out = tmp / "out";
  test::WriteTextFile(out + "/keep.txt", "mine");
  const auto r = test::RunAuvdock(
      {"simulate", "--scenario", WriteShortScenario(tmp, 1.0), "--out", out, "--quiet"});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_THAT(r.err, AllOf(HasSubstr(out), HasSubstr("not empty")));
  EXPECT_EQ(test::ReadTextFile(out + "/keep.txt"), "mine");
  EXPECT_EQ(std::distance(fs::directory_iterator(out), fs::directory_iterator()), 1);
}

TEST(Cli, InterruptedSimulationLeavesNothingBehind) {
  test::TempDir tmp;
  const std::string out = tmp / "out";
  const auto r = test::RunAuvdockAndSignal(
      {"simulate", "--scenario", WriteShortScenario(tmp, 30.0), "--out", out, "--quiet"}, 0.5,
      SIGINT);
  EXPECT_EQ(r.exit_status, 130) << r.err;
  EXPECT_FALSE(fs::exists(out));
  // Only the scenario file remains: no staging folder.
  EXPECT_EQ(std::distance(fs::directory_iterator(tmp.path()), fs::directory_iterator()), 1);
}

}  // namespace
}  // namespace auvdock
