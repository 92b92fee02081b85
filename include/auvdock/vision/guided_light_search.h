// A second look for the dock's lights that a frame's first detection missed, where a pose says
// they must be: a far or dim light whose blob response is below the full-image threshold (which
// must stay high: every weak blob of a cluttered scene would pass), or a very close light larger
// than the full-image scales.
//
// Prediction: with a pose T_C_D and its covariance P_local over (dtheta, dt) (the PnP
// convention: R <- Exp(dtheta) R, t <- t + dt), each dock light not yet identified projects to
//   u_i = pi(R p_i + t),  C_i = J_i P_local J_i^T,  J_i = d pi / d(dtheta, dt)
//       = d pi / d p_C [-[R p_i]x  I],
// and its expected image radius r_i = f radius_m / Z_i. A light is searched when u_i lies in
// the image (margin_px) and in front of the camera (min_depth_m).
//
// Search: within the gate
//   g_i = gate_sigmas sqrt(lambda_max(C_i)) + gate_floor_px   (not searched above max_gate_px)
// a prediction with a detection of the frame inside g_i that is nearer to it than to any other
// prediction is not searched (that light was found, or the blob there was judged already);
// otherwise a window around u_i (the gate plus window_sigmas of the largest scale) goes through the
// light detector with relaxed thresholds (a lower blob response and halo colour, scales from
// s_i / 2 to max_scale_ratio s_i, s_i = sqrt(s_optics^2 + r_i^2 / 2) the blob scale of the disc
// blurred by the optics, and no suppression in a brighter light's halo: the prediction says a
// light is there); every check on shape (a peak, compact, round, not flat-topped) still applies.
// The candidate nearest to u_i within g_i is kept if no detection of the frame lies within the
// larger of the two radii (min_separation_px at least) of it: that would be the same blob,
// which the matcher already judged. At most one detection per light, and one light per
// detection (two lights whose gates share a candidate: the nearer prediction keeps it).
// A light so close that it is a saturated disc, with no peak at the searched scales, is taken
// from the disc (saturated_discs; FindSaturatedDisc).
//
// Units: pixels (raw, distorted image; (0, 0) the centre of the top-left pixel), metres.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "auvdock/camera/pinhole_radtan_camera.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/geometry/pose3.h"
#include "auvdock/vision/blob_light_detector.h"
#include "auvdock/vision/light_detection.h"
#include "auvdock/vision/saturated_disc.h"

namespace auvdock {

struct PredictedLight {
  int light_id = -1;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();  // from the pose's, px^2
  double radius_px = 0.0;                                // expected image radius of the disc
  double depth_m = 0.0;
};

// The dock lights whose id is not in skip_ids, projected by T_C_D (see above); covariance_local
// may be zero (then every C_i is zero).
std::vector<PredictedLight> PredictLights(const DockModel& dock, const PinholeRadtanCamera& camera,
                                          const Pose3& T_C_D,
                                          const Eigen::Matrix<double, 6, 6>& covariance_local,
                                          const std::vector<int>& skip_ids,
                                          double margin_px = 2.0, double min_depth_m = 0.05);

// J = d u / d(dtheta, dt) of the dock point p_D's projection at T_C_D, the left perturbation
// above: d pi / d p_C [-[R p_D]x  I], d pi / d p_C by central differences (the distortion model
// is the camera's business). Zero where the camera cannot project the point's neighbourhood.
Eigen::Matrix<double, 2, 6> ProjectionPoseJacobian(const PinholeRadtanCamera& camera,
                                                   const Pose3& T_C_D, const Eigen::Vector3d& p_D);

// How much larger the identified lights look than the dock's radius_m makes them at T_C_D: the
// median over the identified detections (light_ids[i] >= 0) of radius_px / predicted radius
// (the glow, not the emitting disc, sets a light's blob size); 1 with none.
double ObservedSizeRatio(const DockModel& dock, const PinholeRadtanCamera& camera,
                         const Pose3& T_C_D, const std::vector<LightDetection>& detections,
                         const std::vector<int>& light_ids);

struct GuidedLightSearchOptions {
  double gate_sigmas = 3.0;
  double gate_floor_px = 1.5;  // the light's own centroid error and the pose's unmodelled error
  double max_gate_px = 8.0;    // a prediction this uncertain is no guide
  double min_response = 10.0;  // gray levels: about 20 levels of contrast at the light's scale
  // Of the full-image threshold: a dim light shows its colour in proportion to its contrast.
  double halo_excess_fraction = 0.3;
  double window_sigmas = 4.0;
  // Scales from half the expected blob scale (below) to max_scale_ratio times it: a light's halo
  // and bloom, and a saturated core, make it larger than its disc, never smaller.
  double max_scale_ratio = 4.0;
  int num_scales = 6;
  double min_separation_px = 3.0;
  // Where no blob qualifies, a saturated disc holding the prediction and no other light
  // (saturated_disc.h: a light a few decimetres away), its centroid within the gate plus 3 of
  // its sigmas.
  bool saturated_discs = true;
};

struct GuidedDetection {
  int light_id = -1;
  LightDetection detection;
  double distance_px = 0.0;  // to the prediction
};

class GuidedLightSearch {
 public:
  // full_image_options: the first pass's detector options (colour, core, checks, deinterlace),
  // whose thresholds this search relaxes. Throws std::invalid_argument for options out of range.
  GuidedLightSearch(const BlobLightDetectorOptions& full_image_options,
                    const GuidedLightSearchOptions& options = {});

  // image: the frame the first pass saw (CV_8UC3 or CV_8UC1); existing: its detections.
  // min_halo_excess: the first pass's colour threshold for this image (learned or configured).
  std::vector<GuidedDetection> Search(const cv::Mat& image,
                                      const std::vector<PredictedLight>& predictions,
                                      const std::vector<LightDetection>& existing,
                                      double min_halo_excess) const;

  const GuidedLightSearchOptions& options() const { return options_; }

 private:
  BlobLightDetectorOptions detector_options_;
  GuidedLightSearchOptions options_;
};

// The second look after a pose, as the pipelines use it: the dock's lights not in *light_ids,
// predicted by T_C_D with covariance J P_local J^T + pixel_sigma_px^2 I and sizes scaled by the
// identified lights' ObservedSizeRatio, searched for in image; each found light is appended to
// *detections and *light_ids. Returns how many were appended.
int SearchMissedLights(const GuidedLightSearch& search, const cv::Mat& image,
                       const DockModel& dock, const PinholeRadtanCamera& camera,
                       const Pose3& T_C_D, const Eigen::Matrix<double, 6, 6>& covariance_local,
                       double pixel_sigma_px, double min_halo_excess,
                       std::vector<LightDetection>* detections, std::vector<int>* light_ids);

}  // namespace auvdock
