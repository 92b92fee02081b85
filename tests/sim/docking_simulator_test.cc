#include "auvdock/sim/docking_simulator.h"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "auvdock/io/calibration.h"
#include "auvdock/io/dataset.h"
#include "auvdock/io/light_labels_csv.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_scenarios.h"

namespace fs = std::filesystem;

namespace auvdock {
namespace {

// Every file of a folder (relative path -> bytes).
std::map<std::string, std::string> ReadTree(const std::string& root) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (entry.is_regular_file()) {
      files[fs::relative(entry.path(), root).string()] = test::ReadTextFile(entry.path().string());
    }
  }
  return files;
}

TEST(DockingSimulator, SameSeedGivesByteIdenticalOutputAndOtherSeedsDiffer) {
  test::TempDir tmp;
  Scenario scenario = test::ShortScenario(1.0);
  for (const std::string name : {"a", "b", "c"}) fs::create_directories(tmp / name);
  DockingSimulator(scenario).Run(tmp / "a", CancellationToken());
  DockingSimulator(scenario).Run(tmp / "b", CancellationToken());
  scenario.seed = 2;
  DockingSimulator(scenario).Run(tmp / "c", CancellationToken());
  const auto a = ReadTree(tmp / "a"), b = ReadTree(tmp / "b"), c = ReadTree(tmp / "c");
  ASSERT_GT(a.size(), 20u);  // calibration, dock, sensors, 3 x 11 images, ground truth
  EXPECT_EQ(a, b);
  EXPECT_NE(a.at("imu0/data.csv"), c.at("imu0/data.csv"));
  EXPECT_NE(a.at("cam0/data/1700000000000000000.png"), c.at("cam0/data/1700000000000000000.png"));
  EXPECT_EQ(a.at("groundtruth.tum"), c.at("groundtruth.tum"));  // the trajectory is the scenario's
}

// Each image has its own random stream (seed, camera, frame): the output is the same whatever
// the number of threads that render it (1, 2 or 5 workers: batches of 2, 4 or 10 frames, images
// finished in different orders), and an image the same whatever was rendered before it (a 0.3 s
// run's frames are the first frames of the 1 s run).
TEST(DockingSimulator, TheOutputDoesNotDependOnTheRenderingThreads) {
  test::TempDir tmp;
  const Scenario scenario = test::ShortScenario(1.0);
  std::vector<std::map<std::string, std::string>> runs;
  for (const int workers : {1, 2, 5}) {
    const std::string dir = tmp / ("workers_" + std::to_string(workers));
    fs::create_directories(dir);
    DockingSimulator(scenario).Run(dir, CancellationToken(), {}, workers);
    runs.push_back(ReadTree(dir));
  }
  ASSERT_GT(runs[0].size(), 33u);
  EXPECT_EQ(runs[0], runs[1]);
  EXPECT_EQ(runs[0], runs[2]);
  fs::create_directories(tmp / "short");
  DockingSimulator(test::ShortScenario(0.3)).Run(tmp / "short", CancellationToken(), {}, 3);
  int images = 0;
  for (const auto& [path, bytes] : ReadTree(tmp / "short")) {
    if (path.size() < 4 || path.compare(path.size() - 4, 4, ".png") != 0) continue;
    ASSERT_TRUE(runs[0].count(path)) << path;
    EXPECT_EQ(bytes, runs[0].at(path)) << path;
    ++images;
  }
  EXPECT_EQ(images, 3 * 4);
}

// Each image at its camera's own time (here the mono camera 37 ms after the stereo pair), and
// its labels the lights' projections at that time.
TEST(DockingSimulator, WritesTheLightsOfEveryImageAsLabels) {
  test::TempDir tmp;
  Scenario scenario = test::ShortScenario(1.0);
  scenario.cameras.mono_time_offset_s = 0.037;
  const DockingSimulator simulator(scenario);
  simulator.Run(tmp.path(), CancellationToken());
  for (const CameraCalibration& camera : simulator.calibration().cameras) {
    const LightLabels labels = LoadLightLabels(tmp / ("groundtruth/" + camera.name + "_lights.csv"));
    ASSERT_EQ(labels.size(), 11u) << camera.name;  // every frame, with or without lights
    const int64_t offset_ns = camera.role == CameraRole::kMono ? 37000000 : 0;
    for (const auto& [file, frame_labels] : labels) {
      const int64_t t_ns = std::stoll(file.substr(0, file.find('.')));
      EXPECT_EQ((t_ns - scenario.start_time_ns) % 100000000, offset_ns) << camera.name << file;
      const Pose3 T_D_C = simulator.CameraPose(camera, t_ns);
      ASSERT_TRUE(fs::exists(tmp / (camera.name + "/data/" + file)));
      for (const LightLabel& label : frame_labels) {
        EXPECT_GT(label.range_m, 0.0);
        // The label is the light's projection: some dock light projects there at that range.
        double best = 1e9;
        for (const DockLight& light : scenario.dock.lights) {
          const auto uv = camera.intrinsics.Project(T_D_C.Inverse() * light.p_D);
          if (uv) best = std::min(best, (*uv - label.uv).norm());
        }
        EXPECT_LT(best, 1e-6);
      }
    }
  }
}

TEST(DockingSimulator, RandomisedLooksDifferPerCameraAndTheLensIsInTheCalibration) {
  test::TempDir tmp;
  Scenario scenario = test::ShortScenario(0.2);
  scenario.randomize.enabled = true;
  const DockingSimulator simulator(scenario);
  const auto& cameras = simulator.calibration().cameras;
  EXPECT_NE(cameras[0].intrinsics.distortion(), cameras[1].intrinsics.distortion());
  EXPECT_LE(cameras[0].intrinsics.distortion()[0], -0.1);
  simulator.Run(tmp.path(), CancellationToken());
  const Calibration written = LoadCalibration(tmp / "calibration.yaml");
  EXPECT_EQ(written.cameras[2].intrinsics.distortion(), cameras[2].intrinsics.distortion());
  scenario.randomize.strong_distortion = false;
  EXPECT_EQ(DockingSimulator(scenario).calibration().cameras[0].intrinsics.distortion(),
            scenario.cameras.distortion);
}

TEST(DockingSimulator, WritesEverySensorAtItsRate) {
  test::TempDir tmp;
  const Scenario scenario = test::ShortScenario(2.0);
  const SimulationSummary summary = DockingSimulator(scenario).Run(tmp.path(), CancellationToken());
  EXPECT_EQ(summary.n_imu, 401);
  EXPECT_EQ(summary.n_camera_frames, 21);
  EXPECT_EQ(summary.n_depth, 21);
  EXPECT_EQ(summary.n_dvl, 11);
  EXPECT_EQ(summary.n_acoustic, 3);
  const Dataset ds = LoadDataset(tmp.path());
  EXPECT_EQ(ds.imu.size(), 401u);
  EXPECT_EQ(ds.groundtruth.size(), 401u);
  EXPECT_EQ(ds.camera_frames.at("cam2").size(), 21u);
  EXPECT_EQ(ds.visibility.size(), 21u);
  EXPECT_EQ(ds.imu[1].t_ns - ds.imu[0].t_ns, 5000000);
  for (const auto& frame : ds.camera_frames.at("cam0")) EXPECT_TRUE(fs::exists(frame.path));
  EXPECT_EQ(static_cast<int>(ds.faults.size()), summary.n_faults);
}

TEST(DockingSimulator, DefaultScenarioPassesThroughAllFourStagesInOrder) {
  const DockingSimulator simulator(test::DefaultScenario());
  std::vector<VisibilityStage> sequence;
  std::map<VisibilityStage, int> frames;
  for (int64_t k = 0; k <= 400; ++k) {
    const VisibilityStage stage = simulator.VisibilityAt(simulator.SampleTime(k, 10.0)).stage;
    ++frames[stage];
    if (sequence.empty() || sequence.back() != stage) sequence.push_back(stage);
  }
  const std::vector<VisibilityStage> expected = {VisibilityStage::kStereoOnly,
                                                 VisibilityStage::kBoth,
                                                 VisibilityStage::kMonoOnly,
                                                 VisibilityStage::kNeither};
  EXPECT_EQ(sequence, expected);
  for (const auto stage : expected) EXPECT_GE(frames[stage], 20) << VisibilityStageName(stage);
}

TEST(DockingSimulator, NoiseFreeSensorsAreExact) {
  test::TempDir tmp;
  Scenario scenario = test::ShortScenario(1.0);
  scenario.noise_enabled = false;
  scenario.cameras.render_images = false;
  const DockingSimulator simulator(scenario);
  simulator.Run(tmp.path(), CancellationToken());
  const Dataset ds = LoadDataset(tmp.path());
  EXPECT_TRUE(ds.faults.empty());
  ASSERT_FALSE(ds.depth.empty());
  for (const auto& d : ds.depth) {
    const KinematicState s = simulator.trajectory().At(simulator.Seconds(d.t_ns));
    const Eigen::Vector3d p = s.T_D_B * scenario.depth.T_B_S.p;
    EXPECT_NEAR(d.depth_m, scenario.dock.origin_depth_m + p.z(), 1e-12);
  }
  for (const auto& fix : ds.acoustic) {
    const KinematicState s = simulator.trajectory().At(simulator.Seconds(fix.t_ns));
    EXPECT_LT((fix.p_D - s.T_D_B * scenario.acoustic.T_B_S.p).norm(), 1e-12);
    // Late even without noise: latency is timing, not noise.
    EXPECT_GE(fix.latency_ns, static_cast<int64_t>(scenario.acoustic_faults.latency_min_s * 1e9));
    EXPECT_LE(fix.latency_ns, static_cast<int64_t>(scenario.acoustic_faults.latency_max_s * 1e9));
  }
  for (const auto& v : ds.dvl) {
    const KinematicState s = simulator.trajectory().At(simulator.Seconds(v.t_ns));
    // Rigid-body velocity of the DVL position, rotated into the DVL frame (= B here).
    const Eigen::Vector3d expected =
        s.T_D_B.q.conjugate() * s.v_D + s.omega_B.cross(scenario.dvl.T_B_S.p);
    EXPECT_LT((v.v_S - expected).norm(), 1e-12);
  }
}

// The DVL's long bias episodes and its bottom-lock loss: every biased sample is listed, and
// below the minimum altitude there is no sample at all, each missing one listed.
TEST(DockingSimulator, DvlBiasEpisodesAndBottomLockLossAreListed) {
  test::TempDir tmp;
  Scenario scenario = test::ShortScenario(4.0);
  scenario.dvl_faults.gross_error_probability = 0.0;
  scenario.dvl_faults.bias_rate_per_min = 600.0;  // one starts almost at once
  scenario.dvl_faults.bias_min_s = scenario.dvl_faults.bias_max_s = 1.0;
  DockingSimulator(scenario).Run(tmp.path(), CancellationToken());
  const Dataset ds = LoadDataset(tmp.path());
  int bias = 0;
  for (const auto& f : ds.faults) bias += f.sensor == "dvl0" && f.kind == "bias";
  EXPECT_GE(bias, 3);  // 1 s episodes at 5 Hz
  EXPECT_EQ(ds.dvl.size(), 21u);

  test::TempDir low;
  scenario.dvl_faults.bias_rate_per_min = 0.0;
  scenario.dvl_faults.min_altitude_m = 1000.0;  // always too close
  DockingSimulator(scenario).Run(low.path(), CancellationToken());
  const Dataset none = LoadDataset(low.path());
  int lost = 0;
  for (const auto& f : none.faults) lost += f.sensor == "dvl0" && f.kind == "bottom_lock_lost";
  EXPECT_TRUE(none.dvl.empty());
  EXPECT_EQ(lost, 21);
}

TEST(DockingSimulator, InjectedFaultsAreListed) {
  test::TempDir tmp;
  Scenario scenario = test::ShortScenario(4.0);
  scenario.dvl_faults.gross_error_probability = 0.5;
  scenario.acoustic_faults.outlier_probability = 1.0;
  DockingSimulator(scenario).Run(tmp.path(), CancellationToken());
  const Dataset ds = LoadDataset(tmp.path());
  int dvl = 0, acoustic = 0, camera = 0;
  for (const auto& f : ds.faults) {
    if (f.sensor == "dvl0" && f.kind == "gross_error") ++dvl;
    if (f.sensor == "usbl0" && f.kind == "outlier") ++acoustic;
    if (f.kind == "reflection" || f.kind == "particle") ++camera;
  }
  EXPECT_GT(dvl, 3);
  EXPECT_EQ(acoustic, 5);  // every fix, at t = 0..4 s
  EXPECT_GT(camera, 0);
  for (const auto& fix : ds.acoustic) {  // every fix is off by at least half of outlier_m
    const auto it = std::lower_bound(ds.groundtruth.begin(), ds.groundtruth.end(), fix.t_ns,
                                     [](const GroundTruthState& s, int64_t t) { return s.t_ns < t; });
    ASSERT_NE(it, ds.groundtruth.end());
    const Eigen::Vector3d truth = it->T_D_B * scenario.acoustic.T_B_S.p;
    EXPECT_GT((fix.p_D - truth).norm(), 0.5 * scenario.acoustic_faults.outlier_m - 0.5);
  }
}

TEST(DockingSimulator, CancellationStopsTheRun) {
  test::TempDir tmp;
  std::atomic<bool> flag{true};
  EXPECT_THROW(DockingSimulator(test::ShortScenario(1.0)).Run(tmp.path(), CancellationToken(&flag)),
               Cancelled);
}

}  // namespace
}  // namespace auvdock
