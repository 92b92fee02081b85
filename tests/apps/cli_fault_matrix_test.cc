// The fault matrix of `auvdock run` and `auvdock smooth` (issue "Never crash, never silently
// wrong", item 5): every navigation sensor stream (IMU, depth, DVL, USBL, SBL) that stops, jumps
// forward, runs backwards, repeats, steps back once, holds NaN, Inf, an absurd or a negative
// value, is empty, is missing, holds a line that is not a row, or is cut in the middle of a line;
// the cameras seeing nothing for most of the run; a truncated detections file; a solver held to
// one iteration and a microsecond. Each time the command either goes on (exit 0: every pose and
// covariance finite, the files parse, no unsafe GO against the ground truth, a log that is not
// flooded) or stops with one line naming the file and line (exit 2) and leaves no estimate
// behind. Which of the two is fixed per fault, so that a change of handling fails here.
// (Interrupted runs: cli_detections_replay_test.cc; a corrupt image and an IMU NaN on the image
// path: cli_estimator_test.cc.)
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "auvdock/io/decisions_csv.h"
#include "auvdock/io/pose_covariance_csv.h"
#include "auvdock/io/tum_io.h"
#include "tests/testing/run_command.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_scenarios.h"

namespace fs = std::filesystem;
using ::testing::HasSubstr;

namespace auvdock {
namespace {

using Rows = std::vector<std::string>;  // a CSV file's data rows (its header kept apart)

// 12 s of the default scenario from synthetic detections (no images), with an SBL array, so that
// every navigation sensor has a stream. Made once for the suite.
class FaultMatrix : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = new test::TempDir();
    dataset_ = *tmp_ / "ds";
    const std::string scenario = *tmp_ / "s.yaml";
    test::WriteTextFile(scenario, "name: faults\nduration_s: 12.0\ndock: " +
                                      test::SourcePath("data/docks/t_shape.yaml") +
                                      "\nsbl: {rate_hz: 1.0}\n");
    const auto r = test::RunAuvdock(
        {"simulate", "--scenario", scenario, "--out", dataset_, "--detections-only", "--quiet"});
    ASSERT_EQ(r.exit_status, 0) << r.err;
  }
  static void TearDownTestSuite() { delete tmp_; }

  // A copy of the dataset to break.
  static std::string Copy(const std::string& name) {
    const std::string ds = *tmp_ / name;
    fs::copy(dataset_, ds, fs::copy_options::recursive);
    return ds;
  }

  static test::TempDir* tmp_;
  static std::string dataset_;
};
test::TempDir* FaultMatrix::tmp_ = nullptr;
std::string FaultMatrix::dataset_;

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::string Join(const std::string& header, const Rows& rows) {
  std::string text = header + "\n";
  for (const std::string& row : rows) text += row + "\n";
  return text;
}

int64_t TimeOf(const std::string& row) { return std::stoll(row.substr(0, row.find(','))); }

std::string WithTime(const std::string& row, int64_t t_ns) {
  return std::to_string(t_ns) + row.substr(row.find(','));
}

// The row with its field `column` (clamped to its last) replaced.
std::string WithField(const std::string& row, int column, const std::string& value) {
  std::vector<std::string> fields;
  std::istringstream in(row);
  for (std::string f; std::getline(in, f, ',');) fields.push_back(f);
  fields[std::min<std::size_t>(column, fields.size() - 1)] = value;
  std::string out;
  for (std::size_t i = 0; i < fields.size(); ++i) out += (i ? "," : "") + fields[i];
  return out;
}

// One way a stream goes wrong: the new rows from the old (text faults replace the whole file).
struct StreamFault {
  const char* name;
  int expected_exit;  // 0: the run goes on; 2: one line, nothing written
  std::function<Rows(const Rows&)> rows;
};

Rows Broken(const Rows& rows, const std::function<void(Rows*, std::size_t)>& change) {
  Rows out = rows;
  change(&out, out.size() / 2);
  return out;
}

const std::vector<StreamFault>& StreamFaults() {
  static const std::vector<StreamFault> faults = {
      {"stops", 0, [](const Rows& r) { return Rows(r.begin(), r.begin() + r.size() * 3 / 10); }},
      {"jumps_forward", 0,
       [](const Rows& r) {
         return Broken(r, [](Rows* o, std::size_t m) {
           for (std::size_t i = m; i < o->size(); ++i)
             (*o)[i] = WithTime((*o)[i], TimeOf((*o)[i]) + 5'000'000'000);
         });
       }},
      {"runs_backwards", 0,
       [](const Rows& r) {
         return Broken(r, [](Rows* o, std::size_t m) {
           for (std::size_t i = m; i < o->size(); ++i)
             (*o)[i] = WithTime((*o)[i], TimeOf((*o)[i]) - 3'000'000'000);
         });
       }},
      {"repeats", 0,
       [](const Rows& r) {
         return Broken(r, [](Rows* o, std::size_t m) { o->insert(o->begin() + m, 4, (*o)[m]); });
       }},
      {"steps_back_once", 0,
       [](const Rows& r) {
         return Broken(r, [](Rows* o, std::size_t m) { std::swap((*o)[m], (*o)[m + 1]); });
       }},
      {"nan", 0,
       [](const Rows& r) {
         return Broken(r, [](Rows* o, std::size_t m) { (*o)[m] = WithField((*o)[m], 2, "nan"); });
       }},
      {"inf", 0,
       [](const Rows& r) {
         return Broken(r, [](Rows* o, std::size_t m) { (*o)[m] = WithField((*o)[m], 2, "inf"); });
       }},
      {"absurd", 0,
       [](const Rows& r) {
         return Broken(r, [](Rows* o, std::size_t m) { (*o)[m] = WithField((*o)[m], 2, "1e9"); });
       }},
      {"empty", 0, [](const Rows&) { return Rows{}; }},
  };
  return faults;
}

const StreamFault& FaultNamed(const std::string& name) {
  for (const StreamFault& fault : StreamFaults()) {
    if (fault.name == name) return fault;
  }
  throw std::invalid_argument("no stream fault named " + name);
}

struct RunOutcome {
  test::CommandResult result;
  std::string out;
};

RunOutcome RunOn(const std::string& command, const std::string& ds, const std::string& out) {
  return {test::RunAuvdock({command, "--dataset", ds, "--detections", ds + "/detections.csv",
                            "--out", out, "--quiet"}),
          out};
}

// exit 0: the files parse, every pose and covariance is finite, no GO farther than the landing
// tolerance from the truth, and the log is a few lines, not one per row.
void ExpectWentOn(const RunOutcome& run, const std::string& truth_dataset,
                  const std::string& what) {
  ASSERT_EQ(run.result.exit_status, 0) << what << ": " << run.result.err;
  const Trajectory poses = ReadTumTrajectory(run.out + "/trajectory.tum");
  EXPECT_GE(poses.size(), 30u) << what;
  for (const StampedPose& pose : poses) {
    EXPECT_TRUE(pose.T_D_B.p.allFinite() && pose.T_D_B.q.coeffs().allFinite()) << what;
  }
  for (const StampedPoseCovariance& c : ReadPoseCovarianceCsv(run.out + "/covariance.csv")) {
    EXPECT_TRUE(c.covariance.allFinite()) << what << " at " << c.t_ns;
  }
  EXPECT_FALSE(ReadDecisionsCsv(run.out + "/decisions.csv").empty()) << what;
  EXPECT_LE(Lines(run.result.err).size(), 15u) << what << ":\n" << run.result.err;
  const auto e = test::RunAuvdock({"evaluate", "--dataset", truth_dataset, "--estimate",
                                   run.out + "/trajectory.tum", "--covariance",
                                   run.out + "/covariance.csv", "--decisions",
                                   run.out + "/decisions.csv", "--json"});
  ASSERT_EQ(e.exit_status, 0) << what << ": " << e.err;
  const nlohmann::json report = nlohmann::json::parse(e.out);
  EXPECT_EQ(report.at("decisions").at("n_go_unsafe").get<int>(), 0)
      << what << ": largest lateral error at a GO "
      << report.at("decisions").at("max_lateral_error_at_go_m").get<double>() << " m";
}

// exit 2: one line that names the file and its line; no estimate left behind.
void ExpectStopped(const RunOutcome& run, const std::string& file, const std::string& what) {
  EXPECT_EQ(run.result.exit_status, 2) << what << ": " << run.result.err;
  EXPECT_EQ(Lines(run.result.err).size(), 1u) << what << ":\n" << run.result.err;
  EXPECT_THAT(run.result.err, HasSubstr(file + ": line ")) << what;
  EXPECT_FALSE(fs::exists(run.out + "/trajectory.tum")) << what;
}

TEST_F(FaultMatrix, EveryNavigationStreamGoesWrongInEveryWay) {
  int k = 0;
  for (const char* stream : {"imu0", "depth0", "dvl0", "usbl0", "sbl0"}) {
    const std::vector<std::string> original =
        Lines(test::ReadTextFile(dataset_ + "/" + stream + "/data.csv"));
    ASSERT_GT(original.size(), 10u) << stream;
    const Rows rows(original.begin() + 1, original.end());
    for (const StreamFault& fault : StreamFaults()) {
      const std::string what = std::string(stream) + " " + fault.name;
      const std::string ds = Copy("case" + std::to_string(k++));
      test::WriteTextFile(ds + "/" + stream + "/data.csv", Join(original[0], fault.rows(rows)));
      for (const char* command : {"run", "smooth"}) {
        SCOPED_TRACE(what + " (" + command + ")");
        ExpectWentOn(RunOn(command, ds, ds + "/out_" + command), dataset_, what);
      }
    }
  }
}

TEST_F(FaultMatrix, AMissingStreamIsNoStream) {
  for (const char* stream : {"imu0", "depth0", "dvl0", "usbl0", "sbl0"}) {
    const std::string ds = Copy(std::string("missing_") + stream);
    fs::remove(ds + "/" + stream + "/data.csv");
    for (const char* command : {"run", "smooth"}) {
      ExpectWentOn(RunOn(command, ds, ds + "/out_" + command), dataset_,
                   std::string(stream) + " missing (" + command + ")");
    }
  }
}

TEST_F(FaultMatrix, TextThatIsNotARowStopsWithOneLine) {
  int k = 0;
  for (const char* stream : {"imu0", "depth0", "dvl0", "usbl0", "sbl0"}) {
    const std::string file_text = test::ReadTextFile(dataset_ + "/" + stream + "/data.csv");
    const std::vector<std::string> lines = Lines(file_text);
    std::string garbage;
    for (std::size_t i = 0; i < lines.size(); ++i) {
      garbage += lines[i] + "\n";
      if (i == lines.size() / 2) garbage += "this is not a row\n";
    }
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"a line that is not a row", garbage},
        {"cut in the middle of a line", file_text.substr(0, file_text.size() * 2 / 3)},
    };
    for (const auto& [name, text] : cases) {
      const std::string ds = Copy("text" + std::to_string(k++));
      const std::string file = ds + "/" + stream + "/data.csv";
      test::WriteTextFile(file, text);
      for (const char* command : {"run", "smooth"}) {
        ExpectStopped(RunOn(command, ds, ds + "/out_" + command), file,
                      std::string(stream) + " " + name + " (" + command + ")");
      }
    }
  }
}

// The ranges: a negative slant range is a malformed file (a range cannot be negative), one line.
TEST_F(FaultMatrix, ANegativeRangeIsMalformed) {
  const std::string ds = Copy("negative_range");
  const std::string file = ds + "/sbl0/data.csv";
  const std::vector<std::string> lines = Lines(test::ReadTextFile(file));
  Rows rows(lines.begin() + 1, lines.end());
  rows[rows.size() / 2] = WithField(rows[rows.size() / 2], 2, "-50");
  test::WriteTextFile(file, Join(lines[0], rows));
  const RunOutcome run = RunOn("run", ds, ds + "/out");
  ExpectStopped(run, file, "negative range");
  EXPECT_THAT(run.result.err, HasSubstr("cannot be negative"));
}

// An IMU whose clock jumps back: its later rows carry the times of other motion. Integrated as
// they come, they dragged the estimate 0.5 m off while it said GO (7 unsafe GO in `run`, 34 in
// `smooth`); now the rest of the file is one skipped entry and the run goes on from vision.
TEST_F(FaultMatrix, AnImuClockThatJumpsBackEndsTheImuStream) {
  const std::string ds = Copy("imu_clock");
  const std::string file = ds + "/imu0/data.csv";
  const std::vector<std::string> lines = Lines(test::ReadTextFile(file));
  const Rows rows = FaultNamed("runs_backwards").rows(Rows(lines.begin() + 1, lines.end()));
  test::WriteTextFile(file, Join(lines[0], rows));
  const RunOutcome run = RunOn("run", ds, ds + "/out");
  ExpectWentOn(run, dataset_, "IMU clock jump");
  EXPECT_THAT(run.result.err, HasSubstr("the clock jumped back by"));
  const nlohmann::json summary =
      nlohmann::json::parse(test::ReadTextFile(run.out + "/summary.json"));
  EXPECT_EQ(summary.at("resets").get<int>(), 1);  // one outage, one reset (not one per frame)
  EXPECT_EQ(summary.at("skipped").at("dataset_rows").get<int>(), 1);
}

// Every image of the cameras from t0 + from_s to t0 + to_s listed as "saw nothing".
void BlindTheCameras(const std::string& detections_file, double from_s, double to_s) {
  const std::vector<std::string> lines = Lines(test::ReadTextFile(detections_file));
  const int64_t t0 = TimeOf(lines[1]);
  std::string text = lines[0] + "\n";
  std::string last_blind;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const int64_t t = TimeOf(lines[i]);
    if (t < t0 + static_cast<int64_t>(from_s * 1e9) || t > t0 + static_cast<int64_t>(to_s * 1e9)) {
      text += lines[i] + "\n";
      continue;
    }
    const std::string camera = lines[i].substr(lines[i].find(',') + 1, 4);
    const std::string blind = std::to_string(t) + "," + camera + ",-1,,,,,,,";
    if (blind != last_blind) text += blind + "\n";
    last_blind = blind;
  }
  test::WriteTextFile(detections_file, text);
}

// The cameras see nothing from 2 s to 10 s of the 12 s.
TEST_F(FaultMatrix, CamerasThatSeeNothingForMostOfTheRun) {
  const std::string ds = Copy("blind");
  BlindTheCameras(ds + "/detections.csv", 2.0, 10.0);
  for (const char* command : {"run", "smooth"}) {
    const RunOutcome run = RunOn(command, ds, ds + "/out_" + command);
    ExpectWentOn(run, dataset_, std::string("blind cameras (") + command + ")");
    // Every frame is still a frame: one decision each (NO-GO with a reason while blind).
    EXPECT_EQ(ReadDecisionsCsv(run.out + "/decisions.csv").size(), 121u) << command;
  }
}

// The whole default scenario (40 s), the cameras blind from 2 s to 38 s: the DVL carries the
// estimate, GO for at most max_aided_vision_age_s (10 s) of it, then NO-GO until the lights.
TEST_F(FaultMatrix, CamerasBlindForHalfAMinute) {
  const std::string ds = *tmp_ / "blind40";
  const auto s = test::RunAuvdock({"simulate", "--scenario",
                                   test::SourcePath("data/scenarios/default.yaml"), "--out", ds,
                                   "--detections-only", "--quiet"});
  ASSERT_EQ(s.exit_status, 0) << s.err;
  const std::string truth = *tmp_ / "blind40_truth";
  fs::copy(ds, truth, fs::copy_options::recursive);
  BlindTheCameras(ds + "/detections.csv", 2.0, 38.0);
  for (const char* command : {"run", "smooth"}) {
    const RunOutcome run = RunOn(command, ds, ds + "/out_" + command);
    ExpectWentOn(run, truth, std::string("blind 36 s (") + command + ")");
    int no_vision = 0;
    for (const StampedDecision& d : ReadDecisionsCsv(run.out + "/decisions.csv")) {
      no_vision += !d.go && d.reason.find("no vision for") != std::string::npos;
    }
    EXPECT_GT(no_vision, 200) << command;  // 36 s less the DVL-aided 10 s, at 10 frames/s
  }
}

TEST_F(FaultMatrix, ATruncatedDetectionsFileStopsWithOneLine) {
  const std::string ds = Copy("cut_detections");
  const std::string file = ds + "/detections.csv";
  const std::string text = test::ReadTextFile(file);
  test::WriteTextFile(file, text.substr(0, text.size() * 2 / 3));
  for (const char* command : {"run", "smooth"}) {
    ExpectStopped(RunOn(command, ds, ds + "/out_" + command), file,
                  std::string("cut detections (") + command + ")");
  }
}

// A solver held to one iteration and a microsecond per solve: poorer estimates, still finite,
// and never a GO it cannot back.
TEST_F(FaultMatrix, ASolverThatHitsItsLimit) {
  const std::string config = *tmp_ / "limited.yaml";
  test::WriteTextFile(config,
                      "estimator:\n  max_solver_iterations: 1\n  max_solver_time_s: 0.000001\n");
  for (const char* command : {"run", "smooth"}) {
    const std::string out = *tmp_ / (std::string("limited_") + command);
    const RunOutcome run{
        test::RunAuvdock({command, "--dataset", dataset_, "--detections",
                          dataset_ + "/detections.csv", "--config", config, "--out", out,
                          "--quiet"}),
        out};
    ExpectWentOn(run, dataset_, std::string("solver limit (") + command + ")");
  }
}

}  // namespace
}  // namespace auvdock
