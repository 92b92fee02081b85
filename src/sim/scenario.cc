#include "auvdock/sim/scenario.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "auvdock/io/dock_io.h"
#include "auvdock/io/input_error.h"
#include "auvdock/io/yaml_config.h"
#include "auvdock/sim/random_stream.h"

namespace fs = std::filesystem;

namespace auvdock {

namespace {

constexpr double kDegToRad = M_PI / 180.0;

void ReadOscillation(const ConfigNode& parent, const std::string& key, OscillationConfig* c) {
  const ConfigNode n = parent.ChildOrEmpty(key);
  c->amplitude = n.GetNonNegative("amplitude", c->amplitude);
  c->period_s = n.GetPositive("period_s", c->period_s);
  c->phase_rad = n.GetDouble("phase_rad", c->phase_rad);
}

void ReadTrajectory(const ConfigNode& n, DockingTrajectoryConfig* t) {
  t->start_p_D = n.GetVector<3>("start_p_D", t->start_p_D);
  t->start_speed_mps = n.GetNonNegative("start_speed_mps", t->start_speed_mps);
  t->start_yaw_deg = n.GetDouble("start_yaw_deg", t->start_yaw_deg);
  t->hover_p_D = n.GetVector<3>("hover_p_D", t->hover_p_D);
  t->landed_z_D = n.GetDouble("landed_z_D", t->landed_z_D);
  t->approach_end_s = n.GetPositive("approach_end_s", t->approach_end_s);
  t->descent_start_s = n.GetNonNegative("descent_start_s", t->descent_start_s);
  t->touchdown_s = n.GetPositive("touchdown_s", t->touchdown_s);
  ReadOscillation(n, "current_drift_m", &t->current_drift_m);
  ReadOscillation(n, "heave_m", &t->heave_m);
  ReadOscillation(n, "roll_deg", &t->roll_deg);
  ReadOscillation(n, "pitch_deg", &t->pitch_deg);
  ReadOscillation(n, "yaw_deg", &t->yaw_deg);
  if (!(t->touchdown_s > t->descent_start_s)) {
    n.Fail("touchdown_s", "must be later than descent_start_s");
  }
  if (t->start_p_D.z() >= 0.0) n.Fail("start_p_D", "the vehicle must start above the deck (z < 0)");
  if (t->landed_z_D >= 0.0) n.Fail("landed_z_D", "must be above the deck (z < 0)");
}

double GetProbability(const ConfigNode& n, const std::string& key, double fallback) {
  const double p = n.GetNonNegative(key, fallback);
  if (p > 1.0) n.Fail(key, "a probability must lie in [0, 1]");
  return p;
}

void ReadCameras(const ConfigNode& n, CameraRigConfig* c) {
  if (n.Has("resolution")) {
    const auto r = n.GetDoubles("resolution");
    if (r.size() != 2 || !(r[0] >= 16) || !(r[1] >= 16) || r[0] > 65536 || r[1] > 65536 ||
        r[0] != std::floor(r[0]) || r[1] != std::floor(r[1])) {
      n.Fail("resolution", "expected [width, height], whole pixels, 16 to 65536");
    }
    c->width = static_cast<int>(r[0]);
    c->height = static_cast<int>(r[1]);
  }
  c->rate_hz = n.GetPositive("rate_hz", c->rate_hz);
  c->hfov_deg = n.GetPositive("hfov_deg", c->hfov_deg);
  if (c->hfov_deg >= 170.0) n.Fail("hfov_deg", "must be below 170 degrees for a pinhole camera");
  if (n.Has("distortion")) {
    const auto d = n.GetDoubles("distortion");
    if (d.size() != 4 && d.size() != 5) n.Fail("distortion", "expected [k1, k2, p1, p2(, k3)]");
    c->distortion = {};
    std::copy(d.begin(), d.end(), c->distortion.begin());
  }
  c->pixel_noise_px = n.GetPositive("pixel_noise_px", c->pixel_noise_px);
  c->render_images = n.GetBool("render_images", c->render_images);
  const ConfigNode synthetic = n.ChildOrEmpty("synthetic_detections");
  SyntheticDetectionConfig& d = c->synthetic_detections;
  d.bias_px = synthetic.GetNonNegative("bias_px", d.bias_px);
  d.miss_probability = GetProbability(synthetic, "miss_probability", d.miss_probability);
  d.spurious_per_frame = synthetic.GetNonNegative("spurious_per_frame", d.spurious_per_frame);
  if (d.spurious_per_frame > 100.0) synthetic.Fail("spurious_per_frame", "at most 100");
  d.wrong_id_probability =
      GetProbability(synthetic, "wrong_id_probability", d.wrong_id_probability);
  d.identified = synthetic.GetBool("identified", d.identified);
  const ConfigNode stereo = n.ChildOrEmpty("stereo");
  c->stereo_baseline_m = stereo.GetPositive("baseline_m", c->stereo_baseline_m);
  c->stereo_tilt_deg = stereo.GetDouble("tilt_deg", c->stereo_tilt_deg);
  c->stereo_p_B = stereo.GetVector<3>("p_B", c->stereo_p_B);
  const ConfigNode mono = n.ChildOrEmpty("mono");
  c->mono_p_B = mono.GetVector<3>("p_B", c->mono_p_B);
  c->mono_time_offset_s = mono.GetNonNegative("time_offset_s", c->mono_time_offset_s);
  if (c->mono_time_offset_s * c->rate_hz >= 1.0) {
    mono.Fail("time_offset_s", "must be below the frame interval 1 / rate_hz");
  }
}

void ReadRender(const ConfigNode& n, RenderOptions* r) {
  r->noise_sigma = n.GetNonNegative("noise_sigma", r->noise_sigma);
  r->vignetting = n.GetNonNegative("vignetting", r->vignetting);
  if (r->vignetting >= 1.0) n.Fail("vignetting", "must be below 1");
  r->exposure = n.GetPositive("exposure", r->exposure);
  r->reflections = n.GetBool("reflections", r->reflections);
  r->particles_per_frame = n.GetNonNegative("particles_per_frame", r->particles_per_frame);
}

void ReadRandomization(const ConfigNode& n, RenderRandomization* r) {
  r->enabled = n.GetBool("enabled", r->enabled);
  r->light_appearance = n.GetBool("light_appearance", r->light_appearance);
  r->asymmetric_lobes = n.GetBool("asymmetric_lobes", r->asymmetric_lobes);
  r->dock_structures = n.GetBool("dock_structures", r->dock_structures);
  r->backgrounds = n.GetBool("backgrounds", r->backgrounds);
  r->blur = n.GetBool("blur", r->blur);
  r->interlacing = n.GetBool("interlacing", r->interlacing);
  r->jpeg = n.GetBool("jpeg", r->jpeg);
  r->strong_distortion = n.GetBool("strong_distortion", r->strong_distortion);
}



// `sbl:` (seed 001): four transducers at the corners of an a x b rectangle in the hull's
// bottom plane, T0 (a/2, -b/2), T1 (a/2, b/2), T2 (-a/2, b/2), T3 (-a/2, -b/2), at z = plane_z_m
// in B (x forward, y right, z down).
SblCalibration LoadSbl(const ConfigNode& n, SblFaultConfig* faults) {
  SblCalibration sbl;
  sbl.rate_hz = n.GetPositive("rate_hz", sbl.rate_hz);
  sbl.sigma_min_m = n.GetPositive("sigma_min_m", sbl.sigma_min_m);
  sbl.sigma_range_fraction = n.GetNonNegative("sigma_range_fraction", sbl.sigma_range_fraction);
  const Eigen::Vector2d ab = n.GetVector<2>("array_m", Eigen::Vector2d(0.8, 0.3));
  if (!(ab.x() > 0.0) || !(ab.y() > 0.0) || !ab.allFinite()) {
    n.Fail("array_m", "expected [a, b]: the array's positive length and width (m)");
  }
  const double z = n.GetDouble("plane_z_m", 0.2);
  const double a = 0.5 * ab.x(), b = 0.5 * ab.y();
  sbl.p_B_transducers = {{a, -b, z}, {a, b, z}, {-a, b, z}, {-a, -b, z}};
  faults->min_range_m = n.GetNonNegative("min_range_m", faults->min_range_m);
  faults->dropout_probability =
      GetProbability(n, "dropout_probability", faults->dropout_probability);
  faults->outlier_probability =
      GetProbability(n, "outlier_probability", faults->outlier_probability);
  faults->outlier_m = n.GetNonNegative("outlier_m", faults->outlier_m);
  return sbl;
}

}  // namespace

Scenario LoadScenario(const std::string& path) {
  const ConfigNode root = ConfigNode::LoadFile(path);
  Scenario s;
  s.source_path = path;
  s.name = root.GetString("name", s.name);
  s.duration_s = root.GetPositive("duration_s", s.duration_s);
  s.start_time_ns = root.GetInt64("start_time_ns", s.start_time_ns);
  if (s.start_time_ns < 0) root.Fail("start_time_ns", "must not be negative");
  const int64_t seed = root.GetInt64("seed", static_cast<int64_t>(s.seed));
  if (seed < 0) root.Fail("seed", "must not be negative");
  s.seed = static_cast<uint64_t>(seed);
  s.noise_enabled = root.GetBool("noise", s.noise_enabled);

  s.dock_path = root.GetString("dock");
  const fs::path dock_file = fs::path(path).parent_path() / s.dock_path;
  s.dock = LoadDockModel(dock_file.lexically_normal().string());

  if (!ParseWaterType(root.GetString("water", WaterTypeName(s.water_type)), &s.water_type)) {
    root.Fail("water", "expected clear, coastal or turbid");
  }
  ReadTrajectory(root.ChildOrEmpty("trajectory"), &s.trajectory);
  ReadCameras(root.ChildOrEmpty("cameras"), &s.cameras);
  ReadRender(root.ChildOrEmpty("render"), &s.render);
  ReadRandomization(root.ChildOrEmpty("randomize"), &s.randomize);

  const ConfigNode imu = root.ChildOrEmpty("imu");
  s.imu.rate_hz = imu.GetPositive("rate_hz", s.imu.rate_hz);
  s.imu.gyroscope_noise_density = imu.GetPositive("gyroscope_noise_density", s.imu.gyroscope_noise_density);
  s.imu.gyroscope_random_walk = imu.GetPositive("gyroscope_random_walk", s.imu.gyroscope_random_walk);
  s.imu.accelerometer_noise_density =
      imu.GetPositive("accelerometer_noise_density", s.imu.accelerometer_noise_density);
  s.imu.accelerometer_random_walk =
      imu.GetPositive("accelerometer_random_walk", s.imu.accelerometer_random_walk);
  s.initial_gyro_bias = imu.GetVector<3>("initial_gyro_bias", s.initial_gyro_bias);
  s.initial_accel_bias = imu.GetVector<3>("initial_accel_bias", s.initial_accel_bias);
  const ConfigNode imu_errors = imu.ChildOrEmpty("errors");
  s.imu_errors.noise_scale = imu_errors.GetPositive("noise_scale", s.imu_errors.noise_scale);
  s.imu_errors.gyro_scale_factor =
      imu_errors.GetVector<3>("gyro_scale_factor", s.imu_errors.gyro_scale_factor);
  s.imu_errors.accel_scale_factor =
      imu_errors.GetVector<3>("accel_scale_factor", s.imu_errors.accel_scale_factor);
  s.imu_errors.misalignment_rad =
      imu_errors.GetVector<3>("misalignment_rad", s.imu_errors.misalignment_rad);

  const ConfigNode depth = root.ChildOrEmpty("depth");
  s.depth.rate_hz = depth.GetPositive("rate_hz", s.depth.rate_hz);
  s.depth.sigma_m = depth.GetPositive("sigma_m", s.depth.sigma_m);
  s.depth.T_B_S.p = depth.GetVector<3>("p_B", Eigen::Vector3d(-0.3, 0.0, -0.15));
  s.depth_faults.bias_m = depth.GetDouble("bias_m", s.depth_faults.bias_m);
  s.depth_faults.bias_rate_mps = depth.GetDouble("bias_rate_mps", s.depth_faults.bias_rate_mps);

  const ConfigNode dvl = root.ChildOrEmpty("dvl");
  s.dvl.rate_hz = dvl.GetPositive("rate_hz", s.dvl.rate_hz);
  s.dvl.sigma_mps = dvl.GetPositive("sigma_mps", s.dvl.sigma_mps);
  s.dvl.T_B_S.p = dvl.GetVector<3>("p_B", Eigen::Vector3d(0.1, 0.0, 0.25));
  s.dvl_faults.gross_error_probability =
      GetProbability(dvl, "gross_error_probability", s.dvl_faults.gross_error_probability);
  s.dvl_faults.gross_error_mps = dvl.GetNonNegative("gross_error_mps", s.dvl_faults.gross_error_mps);
  DvlFaultConfig& df = s.dvl_faults;
  df.bias_rate_per_min = dvl.GetNonNegative("bias_rate_per_min", df.bias_rate_per_min);
  df.bias_min_mps = dvl.GetNonNegative("bias_min_mps", df.bias_min_mps);
  df.bias_max_mps = dvl.GetNonNegative("bias_max_mps", df.bias_max_mps);
  if (df.bias_max_mps < df.bias_min_mps) dvl.Fail("bias_max_mps", "must be >= bias_min_mps");
  df.bias_min_s = dvl.GetPositive("bias_min_s", df.bias_min_s);
  df.bias_max_s = dvl.GetPositive("bias_max_s", df.bias_max_s);
  if (df.bias_max_s < df.bias_min_s) dvl.Fail("bias_max_s", "must be >= bias_min_s");
  df.min_altitude_m = dvl.GetNonNegative("min_altitude_m", df.min_altitude_m);

  const ConfigNode ac = root.ChildOrEmpty("acoustic");
  s.acoustic.rate_hz = ac.GetPositive("rate_hz", s.acoustic.rate_hz);
  s.acoustic.sigma_min_m = ac.GetPositive("sigma_min_m", s.acoustic.sigma_min_m);
  s.acoustic.sigma_range_fraction =
      ac.GetNonNegative("sigma_range_fraction", s.acoustic.sigma_range_fraction);
  s.acoustic.T_B_S.p = ac.GetVector<3>("p_B", Eigen::Vector3d(0.0, 0.0, -0.2));
  s.acoustic_faults.outlier_probability =
      GetProbability(ac, "outlier_probability", s.acoustic_faults.outlier_probability);
  s.acoustic_faults.outlier_m = ac.GetNonNegative("outlier_m", s.acoustic_faults.outlier_m);
  s.acoustic_faults.latency_min_s =
      ac.GetNonNegative("latency_min_s", s.acoustic_faults.latency_min_s);
  s.acoustic_faults.latency_max_s =
      ac.GetNonNegative("latency_max_s", s.acoustic_faults.latency_max_s);
  if (s.acoustic_faults.latency_max_s < s.acoustic_faults.latency_min_s) {
    ac.Fail("latency_max_s", "must not be below latency_min_s");
  }
  if (root.Has("sbl")) s.sbl = LoadSbl(root.Child("sbl"), &s.sbl_faults);
  if (root.Has("heading")) {
    const ConfigNode n = root.Child("heading");
    HeadingCalibration heading;
    heading.rate_hz = n.GetPositive("rate_hz", heading.rate_hz);
    heading.sigma_rad = n.GetPositive("sigma_deg", heading.sigma_rad * 180.0 / M_PI) * M_PI / 180.0;
    const double yaw = n.GetDouble("yaw_deg", 0.0) * M_PI / 180.0;
    if (!std::isfinite(yaw)) n.Fail("yaw_deg", "must be finite");
    heading.T_B_S.q = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
    s.heading = heading;
  }

  root.CheckNoUnknownKeys();
  return s;
}

namespace {

// Rotation of a forward-looking OpenCV camera tilted down by `tilt` about its x axis:
// z_C = (cos t, 0, sin t), x_C = (0, 1, 0), y_C = z_C x x_C ... expressed in B (columns).
Eigen::Quaterniond ForwardDownCameraRotation(double tilt) {
  Eigen::Matrix3d R_B_C;
  R_B_C.col(0) = Eigen::Vector3d(0.0, 1.0, 0.0);
  R_B_C.col(1) = Eigen::Vector3d(-std::sin(tilt), 0.0, std::cos(tilt));
  R_B_C.col(2) = Eigen::Vector3d(std::cos(tilt), 0.0, std::sin(tilt));
  return Eigen::Quaterniond(R_B_C);
}

// Down-looking camera, image top towards the bow: z_C = +z_B, x_C = +y_B, y_C = -x_B.
Eigen::Quaterniond DownCameraRotation() {
  Eigen::Matrix3d R_B_C;
  R_B_C.col(0) = Eigen::Vector3d(0.0, 1.0, 0.0);
  R_B_C.col(1) = Eigen::Vector3d(-1.0, 0.0, 0.0);
  R_B_C.col(2) = Eigen::Vector3d(0.0, 0.0, 1.0);
  return Eigen::Quaterniond(R_B_C);
}

}  // namespace

Calibration MakeCalibration(const Scenario& s) {
  const CameraRigConfig& c = s.cameras;
  // Each camera's lens: the configured distortion, or one drawn per camera.
  auto intrinsics_of = [&](int camera_index) {
    std::array<double, 5> distortion = c.distortion;
    if (s.randomize.enabled && s.randomize.strong_distortion) {
      const double half_width = std::tan(0.5 * c.hfov_deg * kDegToRad);
      const double corner = half_width * std::hypot(1.0, static_cast<double>(c.height) / c.width);
      std::mt19937_64 rng = MakeRandomStream(
          s.seed, static_cast<uint64_t>(RandomStreamId::kLensBase) + camera_index);
      distortion = DrawStrongDistortion(corner, rng);
    }
    return PinholeRadtanCamera::FromHorizontalFov(c.width, c.height, c.hfov_deg * kDegToRad,
                                                  distortion);
  };
  Calibration cal;
  const Eigen::Quaterniond q_stereo = ForwardDownCameraRotation(c.stereo_tilt_deg * kDegToRad);
  const Eigen::Vector3d half_baseline(0.0, 0.5 * c.stereo_baseline_m, 0.0);
  cal.cameras.push_back({"cam0", CameraRole::kStereoLeft, intrinsics_of(0),
                         Pose3(q_stereo, c.stereo_p_B - half_baseline), c.rate_hz,
                         c.pixel_noise_px});
  cal.cameras.push_back({"cam1", CameraRole::kStereoRight, intrinsics_of(1),
                         Pose3(q_stereo, c.stereo_p_B + half_baseline), c.rate_hz,
                         c.pixel_noise_px});
  cal.cameras.push_back({"cam2", CameraRole::kMono, intrinsics_of(2),
                         Pose3(DownCameraRotation(), c.mono_p_B), c.rate_hz, c.pixel_noise_px});
  cal.imu = s.imu;
  cal.depth = s.depth;
  cal.dvl = s.dvl;
  cal.acoustic = s.acoustic;
  cal.sbl = s.sbl;
  cal.heading = s.heading;
  return cal;
}

void ScaleFaultRates(double factor, Scenario* s) {
  const auto probability = [factor](double p) { return std::min(1.0, factor * p); };
  s->dvl_faults.gross_error_probability = probability(s->dvl_faults.gross_error_probability);
  s->dvl_faults.bias_rate_per_min *= factor;
  s->acoustic_faults.outlier_probability = probability(s->acoustic_faults.outlier_probability);
  s->sbl_faults.outlier_probability = probability(s->sbl_faults.outlier_probability);
  s->sbl_faults.dropout_probability = probability(s->sbl_faults.dropout_probability);
  SyntheticDetectionConfig& d = s->cameras.synthetic_detections;
  d.miss_probability = probability(d.miss_probability);
  d.spurious_per_frame *= factor;
  d.wrong_id_probability = probability(d.wrong_id_probability);
}

}  // namespace auvdock
