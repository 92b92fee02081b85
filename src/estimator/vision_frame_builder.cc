#include "auvdock/estimator/vision_frame_builder.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "auvdock/vision/stereo_triangulation.h"

namespace auvdock {
namespace {

// Detection index per identified light id; ids seen twice are dropped.
std::map<int, int> IdentifiedLights(const CameraObservation& obs) {
  std::map<int, int> index_of;
  std::map<int, int> count;
  for (std::size_t i = 0; i < obs.detections.size() && i < obs.light_ids.size(); ++i) {
    const int id = obs.light_ids[i];
    if (id < 0) continue;
    index_of[id] = static_cast<int>(i);
    ++count[id];
  }
  for (const auto& [id, n] : count) {
    if (n > 1) index_of.erase(id);
  }
  return index_of;
}

// The detector's own centroid sigma per coordinate, sqrt(trace / 2) (0 when it measures none).
double OwnSigma(const LightDetection& detection) {
  return std::sqrt(std::max(0.0, detection.covariance.trace()) / 2.0);
}

}  // namespace

VisionFrame MakeVisionFrame(const BaselineFrame& frame, const CameraCalibration* left,
                            const CameraCalibration* right, const CameraCalibration* mono) {
  VisionFrame out;
  out.t_ns = frame.t_ns;
  out.T_D_B_initial = frame.T_D_B;
  out.symmetry_unresolved = frame.symmetry_unresolved;
  if (mono) {
    for (const auto& [id, i] : IdentifiedLights(frame.mono)) {
      MonoLightObservation obs;
      obs.light_id = id;
      const LightDetection& detection = frame.mono.detections[i];
      obs.uv = detection.uv;
      // The detector's own centroid covariance when it measures one (never below the camera's
      // figure): a light cut by the border or smeared carries a wider one.
      obs.sigma_px = std::max(mono->pixel_noise_px, OwnSigma(detection));
      out.mono.push_back(obs);
    }
  }
  if (left && right) {
    const std::map<int, int> in_left = IdentifiedLights(frame.left);
    const std::map<int, int> in_right = IdentifiedLights(frame.right);
    for (const auto& [id, l] : in_left) {
      const auto r = in_right.find(id);
      if (r == in_right.end()) continue;
      // As for mono: the detections' own centroid sigma where larger than the camera's, the
      // larger of the two (the triangulation takes one sigma for both images).
      const LightDetection& in_l = frame.left.detections[l];
      const LightDetection& in_r = frame.right.detections[r->second];
      const double sigma_px = std::max({left->pixel_noise_px, OwnSigma(in_l), OwnSigma(in_r)});
      const TriangulatedPoint point =
          TriangulateLinear(in_l.uv, in_r.uv, *left, *right, sigma_px);
      if (!point.ok) continue;
      StereoLightObservation obs;
      obs.light_id = id;
      obs.p_S = point.p_S;
      obs.covariance = point.covariance;
      obs.sigma_px = sigma_px;
      out.stereo.push_back(obs);
    }
  }
  return out;
}

}  // namespace auvdock
