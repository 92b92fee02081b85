// Cost of the per-frame geometric pose solvers on the default dock (6 coplanar lights) seen by
// the default rig (640x512, 70 deg): monocular PnP, and the stereo path (left-right matching,
// linear triangulation with covariance, SVD alignment). Both should be far below a frame
// period (100 ms at 10 Hz); the light detector and the estimator dominate. BM_OpenCvSolvePnpSqpnp
// runs OpenCV's SQPnP on the same correspondences, for time and error side by side (counter
// pos_err_mm: the camera position's error against the truth).
#include <random>
#include <vector>

#include <benchmark/benchmark.h>
#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>

#include "auvdock/sim/scenario.h"
#include "auvdock/vision/pnp_solver.h"
#include "auvdock/vision/point_set_alignment.h"
#include "auvdock/vision/stereo_triangulation.h"

namespace auvdock {
namespace {

Scenario LoadDefault() {
  return LoadScenario(std::string(AUVDOCK_SOURCE_DIR) + "/data/scenarios/default.yaml");
}

// Body 3.5 m behind and 3 m above the dock centre, level: all 6 lights in both stereo images.
Pose3 HoverPose() {
  return Pose3(Eigen::Quaterniond(Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitZ())),
               Eigen::Vector3d(-3.5, 0.1, -3.0));
}

struct View {
  std::vector<Eigen::Vector3d> points_D;
  std::vector<LightDetection> detections;
};

View Render(const Scenario& scenario, const CameraCalibration& camera, std::mt19937* rng) {
  std::normal_distribution<double> noise(0.0, camera.pixel_noise_px);
  const Pose3 T_C_D = (HoverPose() * camera.T_B_C).Inverse();
  View view;
  for (const DockLight& light : scenario.dock.lights) {
    const Eigen::Vector3d p_C = T_C_D * light.p_D;
    const auto uv = camera.intrinsics.Project(p_C);
    if (!uv || !camera.intrinsics.InImage(*uv)) continue;
    LightDetection d;
    d.uv = *uv + Eigen::Vector2d(noise(*rng), noise(*rng));
    d.radius_px = camera.intrinsics.fx() * light.radius_m / p_C.z();
    d.peak = 220.0;
    d.score = 1.0;
    view.points_D.push_back(light.p_D);
    view.detections.push_back(d);
  }
  return view;
}

// The true T_C_D of the hover view.
Pose3 TrueCameraFromDock(const CameraCalibration& camera) {
  return (HoverPose() * camera.T_B_C).Inverse();
}

void BM_SolvePnp(benchmark::State& state) {
  const Scenario scenario = LoadDefault();
  const CameraCalibration camera = MakeCalibration(scenario).cameras[0];
  std::mt19937 rng(1);
  const View view = Render(scenario, camera, &rng);
  std::vector<Eigen::Vector2d> pixels;
  for (const LightDetection& d : view.detections) pixels.push_back(d.uv);
  if (view.points_D.size() != 6) state.SkipWithError("not all 6 lights in view");
  PnpResult result;
  for (auto _ : state) {
    result = SolvePnp(view.points_D, pixels, camera.intrinsics);
    benchmark::DoNotOptimize(result);
    if (!result.ok) state.SkipWithError(result.reason.c_str());
  }
  // The camera position's error against the truth (mm), for the side-by-side with OpenCV.
  const Pose3 truth = TrueCameraFromDock(camera);
  state.counters["pos_err_mm"] = 1e3 * (result.T_C_D.Inverse().p - truth.Inverse().p).norm();
}
BENCHMARK(BM_SolvePnp)->Unit(benchmark::kMicrosecond);

// OpenCV's own building block on the same correspondences: cv::solvePnP with SQPnP (a global
// solver; no covariance). Side by side with BM_SolvePnp in one run: time and the same error.
void BM_OpenCvSolvePnpSqpnp(benchmark::State& state) {
  const Scenario scenario = LoadDefault();
  const CameraCalibration camera = MakeCalibration(scenario).cameras[0];
  std::mt19937 rng(1);
  const View view = Render(scenario, camera, &rng);
  if (view.points_D.size() != 6) state.SkipWithError("not all 6 lights in view");
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (size_t i = 0; i < view.points_D.size(); ++i) {
    object.emplace_back(view.points_D[i].x(), view.points_D[i].y(), view.points_D[i].z());
    image.emplace_back(view.detections[i].uv.x(), view.detections[i].uv.y());
  }
  const auto& k = camera.intrinsics;
  const cv::Matx33d K(k.fx(), 0, k.cx(), 0, k.fy(), k.cy(), 0, 0, 1);
  const auto& d = k.distortion();
  const std::vector<double> distortion(d.begin(), d.end());
  cv::Mat rvec, tvec;
  for (auto _ : state) {
    const bool ok =
        cv::solvePnP(object, image, K, distortion, rvec, tvec, false, cv::SOLVEPNP_SQPNP);
    benchmark::DoNotOptimize(ok);
    if (!ok) state.SkipWithError("cv::solvePnP failed");
  }
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  const cv::Mat camera_in_dock = -R.t() * tvec;
  const Eigen::Vector3d p(camera_in_dock.at<double>(0), camera_in_dock.at<double>(1),
                          camera_in_dock.at<double>(2));
  state.counters["pos_err_mm"] = 1e3 * (p - TrueCameraFromDock(camera).Inverse().p).norm();
}
BENCHMARK(BM_OpenCvSolvePnpSqpnp)->Unit(benchmark::kMicrosecond);

void BM_TriangulateAndAlign(benchmark::State& state) {
  const Scenario scenario = LoadDefault();
  const Calibration calibration = MakeCalibration(scenario);
  const CameraCalibration& left = calibration.cameras[0];
  const CameraCalibration& right = calibration.cameras[1];
  std::mt19937 rng(2);
  const View left_view = Render(scenario, left, &rng);
  const View right_view = Render(scenario, right, &rng);
  if (left_view.points_D.size() != 6 || right_view.points_D.size() != 6) {
    state.SkipWithError("not all 6 lights in view");
  }
  for (auto _ : state) {
    const auto pairs =
        MatchStereoDetections(left_view.detections, right_view.detections, left, right);
    std::vector<Eigen::Vector3d> p_D, p_S;
    std::vector<double> weights;
    for (const auto& [i, j] : pairs) {
      const TriangulatedPoint point =
          TriangulateLinear(left_view.detections[i].uv, right_view.detections[j].uv, left, right,
                            left.pixel_noise_px);
      if (!point.ok) continue;
      p_D.push_back(left_view.points_D[i]);  // light identity from the 2-D/3-D matcher
      p_S.push_back(point.p_S);
      weights.push_back(1.0 / point.covariance.trace());
    }
    const AlignmentResult T_S_D = AlignPointSets(p_D, p_S, weights);
    benchmark::DoNotOptimize(T_S_D);
    if (pairs.size() != 6 || !T_S_D.ok) state.SkipWithError("stereo pose failed");
  }
}
BENCHMARK(BM_TriangulateAndAlign)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace auvdock
