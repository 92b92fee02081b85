#include "euroc_dataset.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "auvdock/io/imu_time_base.h"
#include "auvdock/io/input_error.h"
#include "auvdock/io/pose_from_config.h"
#include "auvdock/io/sensor_csv.h"
#include "auvdock/io/yaml_config.h"

namespace fs = std::filesystem;

namespace auvdock::internal {

namespace {

Pose3 ReadEurocTransform(const ConfigNode& node) {
  const ConfigNode T = node.Child("T_BS");
  if (T.GetInt("rows") != 4 || T.GetInt("cols") != 4) T.Fail("rows", "expected a 4x4 matrix");
  Pose3 pose;
  std::string why;
  if (!TransformFromRowMajor(T.GetDoubles("data"), &pose, &why)) T.Fail("data", why);
  return pose;
}

CameraCalibration ReadEurocCamera(const std::string& name, const std::string& yaml_path) {
  const ConfigNode node = ConfigNode::LoadFile(yaml_path);
  node.GetString("sensor_type", "camera");
  node.GetString("comment", "");
  CameraCalibration cam;
  cam.name = name;
  cam.role = name == "cam0" ? CameraRole::kStereoLeft
                            : (name == "cam1" ? CameraRole::kStereoRight : CameraRole::kOther);
  cam.T_B_C = ReadEurocTransform(node);
  cam.rate_hz = node.GetPositive("rate_hz");
  const auto resolution = node.GetDoubles("resolution");
  if (resolution.size() != 2 || !(resolution[0] >= 1) || !(resolution[1] >= 1) ||
      resolution[0] > 65536 || resolution[1] > 65536 ||
      resolution[0] != std::floor(resolution[0]) || resolution[1] != std::floor(resolution[1])) {
    node.Fail("resolution", "expected [width, height], whole pixels, at most 65536");
  }
  if (node.GetString("camera_model") != "pinhole") {
    node.Fail("camera_model", "only 'pinhole' is supported");
  }
  const auto k = node.GetDoubles("intrinsics");
  if (k.size() != 4 || !(k[0] > 0) || !(k[1] > 0)) {
    node.Fail("intrinsics", "expected [fu, fv, cu, cv]");
  }
  if (node.GetString("distortion_model") != "radial-tangential") {
    node.Fail("distortion_model", "only 'radial-tangential' is supported");
  }
  const auto d = node.GetDoubles("distortion_coefficients");
  if (d.size() != 4 && d.size() != 5) {
    node.Fail("distortion_coefficients", "expected [k1, k2, p1, p2]");
  }
  std::array<double, 5> dist{};
  std::copy(d.begin(), d.end(), dist.begin());
  cam.intrinsics = PinholeRadtanCamera(static_cast<int>(resolution[0]),
                                       static_cast<int>(resolution[1]), k[0], k[1], k[2], k[3],
                                       dist);
  node.CheckNoUnknownKeys();
  return cam;
}

ImuCalibration ReadEurocImu(const std::string& yaml_path) {
  const ConfigNode node = ConfigNode::LoadFile(yaml_path);
  node.GetString("sensor_type", "imu");
  node.GetString("comment", "");
  ImuCalibration imu;
  imu.T_B_S = ReadEurocTransform(node);
  imu.rate_hz = node.GetPositive("rate_hz");
  imu.gyroscope_noise_density = node.GetPositive("gyroscope_noise_density");
  imu.gyroscope_random_walk = node.GetPositive("gyroscope_random_walk");
  imu.accelerometer_noise_density = node.GetPositive("accelerometer_noise_density");
  imu.accelerometer_random_walk = node.GetPositive("accelerometer_random_walk");
  node.CheckNoUnknownKeys();
  return imu;
}

}  // namespace

Dataset LoadEurocDataset(const std::string& mav_dir, std::vector<std::string>* skipped_rows) {
  Dataset ds;
  ds.root = mav_dir;
  ds.layout = DatasetLayout::kEuroc;

  std::vector<std::string> camera_names;
  for (const auto& entry : fs::directory_iterator(mav_dir)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory() && name.rfind("cam", 0) == 0 &&
        fs::exists(entry.path() / "sensor.yaml")) {
      camera_names.push_back(name);
    }
  }
  std::sort(camera_names.begin(), camera_names.end());
  for (const auto& name : camera_names) {
    const fs::path dir = fs::path(mav_dir) / name;
    ds.calibration.cameras.push_back(ReadEurocCamera(name, (dir / "sensor.yaml").string()));
    if (fs::exists(dir / "data.csv")) {
      ds.camera_frames[name] =
          ReadCameraCsv((dir / "data.csv").string(), (dir / "data").string(), skipped_rows);
    }
  }

  const fs::path imu_dir = fs::path(mav_dir) / "imu0";
  if (fs::exists(imu_dir / "sensor.yaml")) {
    ds.calibration.imu = ReadEurocImu((imu_dir / "sensor.yaml").string());
  }
  if (fs::exists(imu_dir / "data.csv")) ds.imu = ReadImuCsv((imu_dir / "data.csv").string(), skipped_rows);
  if (ds.calibration.imu) {
    if (const std::string problem =
            ImuTimeBaseProblem(ds.imu, *ds.calibration.imu, (imu_dir / "data.csv").string());
        !problem.empty()) {
      throw InputError(problem);
    }
  }

  const fs::path gt = fs::path(mav_dir) / "state_groundtruth_estimate0" / "data.csv";
  if (fs::exists(gt)) ds.groundtruth = ReadGroundTruthCsv(gt.string());

  if (ds.calibration.cameras.empty() && ds.imu.empty()) {
    throw InputError(mav_dir + ": no EuRoC camera or IMU folder found");
  }
  return ds;
}

}  // namespace auvdock::internal
