// A real EuRoC/ASL sequence layout (mav0/...) loads: sensor.yaml calibrations, IMU, cameras and
// the state ground truth. The fixture holds EuRoC MH_01's calibration files and a few rows.
#include <filesystem>

#include <gtest/gtest.h>

#include "auvdock/io/dataset.h"
#include "auvdock/io/input_error.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

TEST(EurocDataset, LoadsSequenceFolderAndMavFolder) {
  for (const std::string& dir : {test::SourcePath("tests/data/euroc_mini"),
                                test::SourcePath("tests/data/euroc_mini/mav0")}) {
    const Dataset ds = LoadDataset(dir);
    EXPECT_EQ(ds.layout, DatasetLayout::kEuroc);
    ASSERT_EQ(ds.calibration.cameras.size(), 2u);
    const CameraCalibration& cam0 = ds.calibration.cameras[0];
    EXPECT_EQ(cam0.name, "cam0");
    EXPECT_EQ(cam0.role, CameraRole::kStereoLeft);
    EXPECT_EQ(ds.calibration.cameras[1].role, CameraRole::kStereoRight);
    EXPECT_EQ(cam0.intrinsics.width(), 752);
    EXPECT_DOUBLE_EQ(cam0.intrinsics.fx(), 458.654);
    EXPECT_DOUBLE_EQ(cam0.intrinsics.distortion()[0], -0.28340811);
    EXPECT_NEAR(cam0.T_B_C.p.x(), -0.0216401454975, 1e-15);
    EXPECT_NEAR(cam0.T_B_C.R()(0, 1), -0.999880929698, 1e-9);
    EXPECT_DOUBLE_EQ(cam0.rate_hz, 20.0);
    ASSERT_TRUE(ds.calibration.imu.has_value());
    EXPECT_DOUBLE_EQ(ds.calibration.imu->gyroscope_noise_density, 1.6968e-04);
    ASSERT_EQ(ds.imu.size(), 3u);
    EXPECT_EQ(ds.imu[0].t_ns, 1403636579758555392);
    EXPECT_DOUBLE_EQ(ds.imu[0].accel.x(), 8.1476917083333333);
    ASSERT_EQ(ds.camera_frames.at("cam1").size(), 3u);
    EXPECT_NE(ds.camera_frames.at("cam1")[0].path.find("mav0/cam1/data/1403636579763555584.png"),
              std::string::npos);
    ASSERT_EQ(ds.groundtruth.size(), 3u);
    EXPECT_DOUBLE_EQ(ds.groundtruth[0].T_D_B.p.x(), 4.688319);
    EXPECT_NEAR(ds.groundtruth[0].T_D_B.q.w(), 0.534108 / Eigen::Vector4d(0.534108, -0.153029, -0.827383, -0.082152).norm(), 1e-12);
    EXPECT_DOUBLE_EQ(ds.groundtruth[0].accel_bias.z(), 0.075593);
    EXPECT_FALSE(ds.dock.has_value());
    EXPECT_TRUE(ds.visibility.empty());
  }
}

// A EuRoC sequence has no dock; the user's dock.yaml beside mav0/ is read, whichever of the two
// folders is given, and a malformed one names itself.
TEST(EurocDataset, ADockFileBesideTheSequenceIsItsDock) {
  namespace fs = std::filesystem;
  test::TempDir tmp;
  const fs::path sequence = fs::path(tmp.path()) / "MH_01";
  fs::copy(test::SourcePath("tests/data/euroc_mini"), sequence, fs::copy_options::recursive);
  fs::copy_file(test::SourcePath("data/docks/t_shape.yaml"), sequence / "dock.yaml");
  for (const fs::path& dir : {sequence, sequence / "mav0"}) {
    const Dataset ds = LoadDataset(dir.string());
    ASSERT_TRUE(ds.dock.has_value()) << dir;
    EXPECT_GE(ds.dock->lights.size(), 4u);
  }
  test::WriteTextFile((sequence / "dock.yaml").string(), "lights: [1, 2\n");
  try {
    LoadDataset(sequence.string());
    FAIL() << "a malformed dock.yaml loaded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("dock.yaml"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace auvdock
