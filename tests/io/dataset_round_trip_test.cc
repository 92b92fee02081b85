// Dataset write -> read round trip: everything written is read back identically.
#include <filesystem>

#include <gtest/gtest.h>
#include <gmock/gmock.h>
#include <opencv2/imgcodecs.hpp>

#include "auvdock/io/dataset.h"
#include "auvdock/io/dataset_writer.h"
#include "auvdock/io/input_error.h"
#include "auvdock/io/staged_directory.h"
#include "auvdock/sim/scenario.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_scenarios.h"

namespace fs = std::filesystem;

namespace auvdock {
namespace {

void ExpectPoseEq(const Pose3& a, const Pose3& b) {
  EXPECT_LT((a.p - b.p).norm(), 1e-15);
  EXPECT_LT((a.q.coeffs() - b.q.coeffs()).norm(), 1e-15);
}

TEST(DatasetRoundTrip, EveryRecordReadsBackIdentically) {
  test::TempDir tmp;
  Scenario scenario = test::DefaultScenario();
  scenario.heading = HeadingCalibration{};  // an AHRS turned 5 degrees to starboard, 1.5 deg
  scenario.heading->sigma_rad = 0.026;
  scenario.heading->T_B_S.q = Eigen::Quaterniond(Eigen::AngleAxisd(0.087, Eigen::Vector3d::UnitZ()));
  scenario.dock.heading_rad = -2.4;  // the dock's x axis heads 137.5 degrees west of north
  const Calibration calibration = MakeCalibration(scenario);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  auto v3 = [&] { return Eigen::Vector3d(u(rng), u(rng), u(rng)); };

  std::vector<ImuSample> imu;
  std::vector<GroundTruthState> gt;
  std::vector<DepthMeasurement> depth;
  std::vector<DvlMeasurement> dvl;
  std::vector<HeadingMeasurement> heading;
  std::vector<AcousticFix> acoustic;
  std::vector<VisibilityRecord> visibility;
  std::vector<FaultRecord> faults;
  cv::Mat image(64, 80, CV_8UC3);
  cv::randu(image, 0, 255);
  {
    DatasetWriter writer(tmp.path(), calibration, scenario.dock);
    for (int k = 0; k < 50; ++k) {
      const int64_t t = 1700000000000000000 + k * 5000000 + (k % 3);
      imu.push_back({t, v3() * 1e-3, v3() / 7.0});
      gt.push_back({t, Pose3(Eigen::Quaterniond(Eigen::Vector4d(v3().x(), u(rng), u(rng), 2.0).normalized()), v3()),
                    v3(), v3() * 1e-4, v3() * 1e-2});
      depth.push_back({t, 30.0 + u(rng)});
      dvl.push_back({t, v3() / 3.0});
      heading.push_back({t, u(rng)});
      acoustic.push_back({t, v3(), 0.05 + std::abs(u(rng)), 200000000 + 1000 * k});
      visibility.push_back({t, k % 7, k % 5, k % 4,
                            StageFromLightCounts(k % 7, k % 5, k % 4)});
      faults.push_back({t, "dvl0", "gross_error", "dv=0.1;0.2;0.3"});
      writer.AddImu(imu.back());
      writer.AddGroundTruth(gt.back());
      writer.AddDepth(depth.back());
      writer.AddDvl(dvl.back());
      writer.AddHeading(heading.back());
      writer.AddAcoustic(acoustic.back());
      writer.AddVisibility(visibility.back());
      writer.AddFault(faults.back());
      if (k < 3) {
        for (const auto& cam : calibration.cameras) writer.AddImage(cam.name, t, image);
      }
    }
    writer.Close();
  }
  const Dataset ds = LoadDataset(tmp.path());
  EXPECT_EQ(ds.layout, DatasetLayout::kAuvdock);
  ASSERT_EQ(ds.imu.size(), imu.size());
  for (std::size_t i = 0; i < imu.size(); ++i) {
    EXPECT_EQ(ds.imu[i].t_ns, imu[i].t_ns);
    EXPECT_EQ(ds.imu[i].gyro, imu[i].gyro);  // bit-exact: shortest round-trip formatting
    EXPECT_EQ(ds.imu[i].accel, imu[i].accel);
    EXPECT_EQ(ds.groundtruth[i].t_ns, gt[i].t_ns);
    ExpectPoseEq(ds.groundtruth[i].T_D_B, gt[i].T_D_B);
    EXPECT_EQ(ds.groundtruth[i].v_D, gt[i].v_D);
    EXPECT_EQ(ds.groundtruth[i].gyro_bias, gt[i].gyro_bias);
    EXPECT_EQ(ds.groundtruth[i].accel_bias, gt[i].accel_bias);
    EXPECT_EQ(ds.depth[i].depth_m, depth[i].depth_m);
    EXPECT_EQ(ds.dvl[i].v_S, dvl[i].v_S);
    EXPECT_EQ(ds.heading[i].t_ns, heading[i].t_ns);
    EXPECT_EQ(ds.heading[i].heading_rad, heading[i].heading_rad);
    EXPECT_EQ(ds.acoustic[i].p_D, acoustic[i].p_D);
    EXPECT_EQ(ds.acoustic[i].sigma_m, acoustic[i].sigma_m);
    EXPECT_EQ(ds.acoustic[i].latency_ns, acoustic[i].latency_ns);
    EXPECT_EQ(ds.visibility[i].stage, visibility[i].stage);
    EXPECT_EQ(ds.visibility[i].n_mono, visibility[i].n_mono);
    EXPECT_EQ(ds.faults[i].detail, faults[i].detail);
  }
  // Calibration and dock.
  ASSERT_EQ(ds.calibration.cameras.size(), calibration.cameras.size());
  for (std::size_t i = 0; i < calibration.cameras.size(); ++i) {
    const auto& a = ds.calibration.cameras[i];
    const auto& b = calibration.cameras[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.role, b.role);
    EXPECT_EQ(a.intrinsics.K(), b.intrinsics.K());
    EXPECT_EQ(a.intrinsics.distortion(), b.intrinsics.distortion());
    EXPECT_EQ(a.intrinsics.width(), b.intrinsics.width());
    EXPECT_LT((a.T_B_C.Matrix() - b.T_B_C.Matrix()).norm(), 1e-15);
  }
  EXPECT_EQ(ds.calibration.imu->accelerometer_random_walk, calibration.imu->accelerometer_random_walk);
  EXPECT_EQ(ds.calibration.acoustic->sigma_range_fraction, calibration.acoustic->sigma_range_fraction);
  ASSERT_TRUE(ds.calibration.heading.has_value());
  EXPECT_EQ(ds.calibration.heading->name, "ahrs0");
  EXPECT_EQ(ds.calibration.heading->sigma_rad, calibration.heading->sigma_rad);
  EXPECT_LT((ds.calibration.heading->T_B_S.Matrix() - calibration.heading->T_B_S.Matrix()).norm(),
            1e-15);
  ASSERT_EQ(ds.heading.size(), heading.size());
  ASSERT_TRUE(ds.dock.has_value());
  ASSERT_EQ(ds.dock->lights.size(), scenario.dock.lights.size());
  for (std::size_t i = 0; i < scenario.dock.lights.size(); ++i) {
    EXPECT_EQ(ds.dock->lights[i].id, scenario.dock.lights[i].id);
    EXPECT_EQ(ds.dock->lights[i].p_D, scenario.dock.lights[i].p_D);
  }
  EXPECT_EQ(ds.dock->gravity_D, scenario.dock.gravity_D);
  EXPECT_NEAR(ds.dock->heading_rad, scenario.dock.heading_rad, 1e-15);
  // Images are lossless.
  ASSERT_EQ(ds.camera_frames.at("cam1").size(), 3u);
  const cv::Mat back = cv::imread(ds.camera_frames.at("cam1")[2].path, cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(back.empty());
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0.0);
}

TEST(DatasetRoundTrip, MalformedRowsNameFileAndLine) {
  test::TempDir tmp;
  const Scenario scenario = test::DefaultScenario();
  { DatasetWriter writer(tmp.path(), MakeCalibration(scenario), scenario.dock); }
  const std::string imu = tmp / "imu0/data.csv";
  test::WriteTextFile(imu, test::ReadTextFile(imu) + "100,0,0,0,0,0,9.8\n200,0,0,nan,0,0,9.8\n");
  try {
    LoadDataset(tmp.path());
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::AllOf(::testing::HasSubstr("imu0/data.csv: line 3"),
                                           ::testing::HasSubstr("w_RS_S_z")));
  }
  test::WriteTextFile(imu, "#h\n200,0,0,0,0,0,9.8\n100,0,0,0,0,0,9.8\n");
  EXPECT_THROW(LoadDataset(tmp.path()), InputError);  // out of order
  test::WriteTextFile(imu, "#h\n200,0,0,0,0,0\n");
  EXPECT_THROW(LoadDataset(tmp.path()), InputError);  // missing column
}

TEST(StagedDirectory, AppearsOnlyOnCommitAndRefusesNonEmptyFolders) {
  test::TempDir tmp;
  const std::string out = tmp / "out";
  {
    StagedDirectory staged(out);
    test::WriteTextFile(staged.staging_path() + "/x.txt", "x");
    EXPECT_FALSE(fs::exists(out));
  }  // not committed: removed
  EXPECT_FALSE(fs::exists(out));
  EXPECT_TRUE(fs::is_empty(tmp.path()));
  {
    StagedDirectory staged(out);
    test::WriteTextFile(staged.staging_path() + "/x.txt", "x");
    staged.Commit();
  }
  EXPECT_TRUE(fs::exists(out + "/x.txt"));
  EXPECT_THROW(StagedDirectory{out}, InputError);  // not empty now
  fs::create_directories(tmp / "empty");
  EXPECT_NO_THROW(StagedDirectory{tmp / "empty"});
}

}  // namespace
}  // namespace auvdock
