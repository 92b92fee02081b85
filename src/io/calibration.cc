#include "auvdock/io/calibration.h"

#include <yaml-cpp/yaml.h>

#include "auvdock/io/input_error.h"
#include "auvdock/io/pose_from_config.h"
#include "auvdock/io/yaml_config.h"
#include "auvdock/io/yaml_writer.h"

namespace auvdock {

const CameraCalibration* Calibration::FindCamera(const std::string& name) const {
  for (const auto& c : cameras) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

const CameraCalibration* Calibration::FindCameraByRole(CameraRole role) const {
  for (const auto& c : cameras) {
    if (c.role == role) return &c;
  }
  return nullptr;
}

namespace {

CameraCalibration ReadCamera(const ConfigNode& node) {
  CameraCalibration cam;
  cam.name = node.GetString("name");
  if (!ParseCameraRole(node.GetString("role", "other"), &cam.role)) {
    node.Fail("role", "expected stereo_left, stereo_right, mono or other");
  }
  const auto resolution = node.GetDoubles("resolution");
  constexpr double kMaxImageSide = 1 << 16;  // before the cast to int (found by fuzzing)
  if (resolution.size() != 2 || !(resolution[0] >= 1) || !(resolution[1] >= 1) ||
      resolution[0] > kMaxImageSide || resolution[1] > kMaxImageSide ||
      resolution[0] != static_cast<int>(resolution[0]) ||
      resolution[1] != static_cast<int>(resolution[1])) {
    node.Fail("resolution", "expected [width, height] in whole pixels, at most 65536");
  }
  const auto model = node.GetString("camera_model", "pinhole");
  if (model != "pinhole") node.Fail("camera_model", "only 'pinhole' is supported");
  const auto intrinsics = node.GetDoubles("intrinsics");
  if (intrinsics.size() != 4 || !(intrinsics[0] > 0) || !(intrinsics[1] > 0)) {
    node.Fail("intrinsics", "expected [fx, fy, cx, cy] with positive focal lengths");
  }
  const auto distortion_model = node.GetString("distortion_model");
  if (distortion_model != "radial-tangential" && distortion_model != "radtan") {
    node.Fail("distortion_model", "only 'radial-tangential' is supported");
  }
  const auto coefficients = node.GetDoubles("distortion_coefficients");
  if (coefficients.size() != 4 && coefficients.size() != 5) {
    node.Fail("distortion_coefficients", "expected [k1, k2, p1, p2] or [k1, k2, p1, p2, k3]");
  }
  std::array<double, 5> d{};
  std::copy(coefficients.begin(), coefficients.end(), d.begin());
  cam.intrinsics = PinholeRadtanCamera(static_cast<int>(resolution[0]),
                                       static_cast<int>(resolution[1]), intrinsics[0],
                                       intrinsics[1], intrinsics[2], intrinsics[3], d);
  cam.T_B_C = GetTransform(node, "T_B_S");
  cam.rate_hz = node.GetPositive("rate_hz");
  cam.pixel_noise_px = node.GetPositive("pixel_noise_px", cam.pixel_noise_px);
  return cam;
}

}  // namespace

Calibration LoadCalibration(const std::string& path) {
  const ConfigNode root = ConfigNode::LoadFile(path);
  Calibration calibration;
  if (root.Has("cameras")) {
    for (const ConfigNode& node : root.Children("cameras")) {
      CameraCalibration cam = ReadCamera(node);
      if (calibration.FindCamera(cam.name)) node.Fail("name", "duplicate camera '" + cam.name + "'");
      calibration.cameras.push_back(cam);
    }
  }
  if (root.Has("imu")) {
    const ConfigNode n = root.Child("imu");
    ImuCalibration imu;
    imu.name = n.GetString("name", imu.name);
    imu.T_B_S = GetTransform(n, "T_B_S", imu.T_B_S);
    if (imu.T_B_S.p.norm() > 1e-9 || imu.T_B_S.q.angularDistance(Eigen::Quaterniond::Identity()) > 1e-9) {
      n.Fail("T_B_S", "the body frame is the IMU frame: T_B_S must be the identity");
    }
    imu.rate_hz = n.GetPositive("rate_hz");
    imu.gyroscope_noise_density = n.GetPositive("gyroscope_noise_density");
    imu.gyroscope_random_walk = n.GetPositive("gyroscope_random_walk");
    imu.accelerometer_noise_density = n.GetPositive("accelerometer_noise_density");
    imu.accelerometer_random_walk = n.GetPositive("accelerometer_random_walk");
    imu.gyroscope_range = n.GetPositive("gyroscope_range", imu.gyroscope_range);
    imu.accelerometer_range = n.GetPositive("accelerometer_range", imu.accelerometer_range);
    calibration.imu = imu;
  }
  if (root.Has("depth")) {
    const ConfigNode n = root.Child("depth");
    DepthCalibration depth;
    depth.name = n.GetString("name", depth.name);
    depth.T_B_S = GetTransform(n, "T_B_S", depth.T_B_S);
    depth.rate_hz = n.GetPositive("rate_hz");
    depth.sigma_m = n.GetPositive("sigma_m");
    calibration.depth = depth;
  }
  if (root.Has("dvl")) {
    const ConfigNode n = root.Child("dvl");
    DvlCalibration dvl;
    dvl.name = n.GetString("name", dvl.name);
    dvl.T_B_S = GetTransform(n, "T_B_S", dvl.T_B_S);
    dvl.rate_hz = n.GetPositive("rate_hz");
    dvl.sigma_mps = n.GetPositive("sigma_mps");
    calibration.dvl = dvl;
  }
  if (root.Has("heading")) {
    const ConfigNode n = root.Child("heading");
    HeadingCalibration heading;
    heading.name = n.GetString("name", heading.name);
    heading.T_B_S = GetTransform(n, "T_B_S", heading.T_B_S);
    heading.rate_hz = n.GetPositive("rate_hz");
    heading.sigma_rad = n.GetPositive("sigma_rad");
    calibration.heading = heading;
  }
  if (root.Has("acoustic")) {
    const ConfigNode n = root.Child("acoustic");
    AcousticCalibration ac;
    ac.name = n.GetString("name", ac.name);
    ac.T_B_S = GetTransform(n, "T_B_S", ac.T_B_S);
    ac.rate_hz = n.GetPositive("rate_hz");
    ac.sigma_min_m = n.GetPositive("sigma_min_m");
    ac.sigma_range_fraction = n.GetNonNegative("sigma_range_fraction", 0.0);
    calibration.acoustic = ac;
  }
  if (root.Has("sbl")) {
    const ConfigNode n = root.Child("sbl");
    SblCalibration sbl;
    sbl.name = n.GetString("name", sbl.name);
    sbl.rate_hz = n.GetPositive("rate_hz");
    sbl.sigma_min_m = n.GetPositive("sigma_min_m");
    sbl.sigma_range_fraction = n.GetNonNegative("sigma_range_fraction", 0.0);
    for (const ConfigNode& t : n.Children("transducers")) {
      const Eigen::Vector3d p_B = t.GetVector<3>("p_B");
      if (!p_B.allFinite()) t.Fail("p_B", "expected 3 finite numbers");
      sbl.p_B_transducers.push_back(p_B);
      t.CheckNoUnknownKeys();
    }
    if (sbl.p_B_transducers.empty() || sbl.p_B_transducers.size() > 16) {
      n.Fail("transducers", "expected 1 to 16 transducers");
    }
    calibration.sbl = sbl;
  }
  root.CheckNoUnknownKeys();
  return calibration;
}

void SaveCalibration(const Calibration& calibration, const std::string& path) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "cameras" << YAML::Value << YAML::BeginSeq;
  for (const auto& cam : calibration.cameras) {
    const auto& k = cam.intrinsics;
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << cam.name;
    out << YAML::Key << "role" << YAML::Value << CameraRoleName(cam.role);
    EmitNumbers(out, "resolution", {double(k.width()), double(k.height())});
    out << YAML::Key << "camera_model" << YAML::Value << "pinhole";
    EmitNumbers(out, "intrinsics", {k.fx(), k.fy(), k.cx(), k.cy()});
    out << YAML::Key << "distortion_model" << YAML::Value << "radial-tangential";
    const auto& d = k.distortion();
    EmitNumbers(out, "distortion_coefficients", {d[0], d[1], d[2], d[3], d[4]});
    EmitNumber(out, "rate_hz", cam.rate_hz);
    EmitNumber(out, "pixel_noise_px", cam.pixel_noise_px);
    EmitTransform(out, "T_B_S", cam.T_B_C);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  if (calibration.imu) {
    const auto& imu = *calibration.imu;
    out << YAML::Key << "imu" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << imu.name;
    EmitNumber(out, "rate_hz", imu.rate_hz);
    EmitNumber(out, "gyroscope_noise_density", imu.gyroscope_noise_density);
    EmitNumber(out, "gyroscope_random_walk", imu.gyroscope_random_walk);
    EmitNumber(out, "accelerometer_noise_density", imu.accelerometer_noise_density);
    EmitNumber(out, "accelerometer_random_walk", imu.accelerometer_random_walk);
    EmitNumber(out, "gyroscope_range", imu.gyroscope_range);
    EmitNumber(out, "accelerometer_range", imu.accelerometer_range);
    EmitTransform(out, "T_B_S", imu.T_B_S);
    out << YAML::EndMap;
  }
  if (calibration.depth) {
    const auto& s = *calibration.depth;
    out << YAML::Key << "depth" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << s.name;
    EmitNumber(out, "rate_hz", s.rate_hz);
    EmitNumber(out, "sigma_m", s.sigma_m);
    EmitTransform(out, "T_B_S", s.T_B_S);
    out << YAML::EndMap;
  }
  if (calibration.dvl) {
    const auto& s = *calibration.dvl;
    out << YAML::Key << "dvl" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << s.name;
    EmitNumber(out, "rate_hz", s.rate_hz);
    EmitNumber(out, "sigma_mps", s.sigma_mps);
    EmitTransform(out, "T_B_S", s.T_B_S);
    out << YAML::EndMap;
  }
  if (calibration.heading) {
    const auto& s = *calibration.heading;
    out << YAML::Key << "heading" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << s.name;
    EmitNumber(out, "rate_hz", s.rate_hz);
    EmitNumber(out, "sigma_rad", s.sigma_rad);
    EmitTransform(out, "T_B_S", s.T_B_S);
    out << YAML::EndMap;
  }
  if (calibration.acoustic) {
    const auto& s = *calibration.acoustic;
    out << YAML::Key << "acoustic" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << s.name;
    EmitNumber(out, "rate_hz", s.rate_hz);
    EmitNumber(out, "sigma_min_m", s.sigma_min_m);
    EmitNumber(out, "sigma_range_fraction", s.sigma_range_fraction);
    EmitTransform(out, "T_B_S", s.T_B_S);
    out << YAML::EndMap;
  }
  if (calibration.sbl) {
    const auto& s = *calibration.sbl;
    out << YAML::Key << "sbl" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << s.name;
    EmitNumber(out, "rate_hz", s.rate_hz);
    EmitNumber(out, "sigma_min_m", s.sigma_min_m);
    EmitNumber(out, "sigma_range_fraction", s.sigma_range_fraction);
    out << YAML::Key << "transducers" << YAML::Value << YAML::BeginSeq;
    for (const Eigen::Vector3d& p : s.p_B_transducers) {
      out << YAML::BeginMap;
      EmitVector3(out, "p_B", p);
      out << YAML::EndMap;
    }
    out << YAML::EndSeq << YAML::EndMap;
  }
  out << YAML::EndMap;
  WriteYamlFile(path,
                "auvdock calibration (docs/dataset_format.md).\n"
                "Body frame B = IMU frame: x forward, y right, z down. T_B_S: sensor S -> body B,\n"
                "row-major 4x4. Cameras: OpenCV frame (x right, y down, z optical axis),\n"
                "intrinsics [fx, fy, cx, cy] px, distortion [k1, k2, p1, p2, k3] (OpenCV order).\n"
                "IMU noise: continuous-time densities (Kalibr/EuRoC units).",
                out);
}

}  // namespace auvdock
