// The source paper's per-frame pose pipeline, end to end (seed 000, sections 2-3; seed 004's
// stereo-to-mono handoff), kept as the baseline the estimator has to beat and as its source of
// initial values.
//
// Per frame (three synchronized images: stereo left, stereo right, mono):
//   1. detect guide lights in every image (LightDetector; optional dark-channel dehazing);
//   2. identify them: the left (else right) stereo image and the mono image are matched to the
//      dock model by hypothesise-and-verify (MatchRansac; the paper's omnidirectional matcher is
//      selectable), the other stereo image inherits the identities through left-right matching
//      on the epipolar line (MatchStereoDetections, seed 004);
//   3. stereo pose: triangulate the identified pairs (TriangulateLinear, eqs. 11-16) in the left
//      camera frame S and align them to the dock lights by SVD (AlignPointSets, eqs. 17-23):
//      T_D_S, then T_D_B = T_D_S T_B_S^-1 (S is cam0);
//   4. mono pose: PnP by Levenberg-Marquardt (SolvePnp, eq. 10) from the matcher's pose:
//      T_C_D, then T_D_B = T_C_D^-1 T_B_C^-1;
//   4b. tracking (optional, on by default): when the hypothesise-and-verify matcher cannot
//      identify an image (too few lights in general position, ambiguity) and the previous
//      frame's pose is recent, the dock is projected with that pose and the detections are
//      assigned by gated Hungarian (MatchByPrediction); PnP then starts from the prediction, so
//      3 identified mono lights suffice. This departs from the paper's frame-independent
//      matching only where that matching has no answer;
//   5. stage logic (section 3.1): stereo usable with >= 3 non-collinear triangulated lights,
//      mono usable with a verified match of >= 4 lights. Stereo only / mono only: that pose.
//      Both: the paper's post-hoc weighted average, weights by the number of lights each
//      camera system sees, w_s = n_s / (n_s + n_m): position averaged, rotation by slerp.
//      Neither: no pose ("pause the pose estimate").
// Frames: D dock (z down), B body, C camera (OpenCV). Units: metres, radians, pixels.
#pragma once

#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "auvdock/geometry/dock_model.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"
#include "auvdock/vision/light_detector.h"
#include "auvdock/vision/ransac_matcher.h"
#include "auvdock/vision/stereo_triangulation.h"
#include "auvdock/vision/tracking_matcher.h"

namespace auvdock {

enum class BaselineMatcher { kRansac, kOmnidirectional };

struct PaperBaselineOptions {
  LightDetectorOptions detector;
  BaselineMatcher matcher = BaselineMatcher::kRansac;
  RansacMatcherOptions ransac;
  StereoMatchOptions stereo;
  int min_stereo_lights = 3;  // triangulated, non-collinear
  int min_mono_lights = 4;    // a unique PnP (3 when tracking supplies the initial pose)
  bool use_tracking = true;
  double tracking_max_age_s = 0.5;  // a previous pose older than this predicts nothing
  TrackingMatcherOptions tracking;
  uint64_t seed = 1;          // the matcher's random subsets (deterministic)
};

// What one camera saw and how its lights were identified.
struct CameraObservation {
  std::vector<LightDetection> detections;
  std::vector<int> light_ids;  // per detection: dock light id, or -1 when not identified
  MatchStatus status = MatchStatus::kFailed;
  std::string reason;
  bool tracked = false;  // identified by prediction (tracking) rather than from scratch
  int num_identified() const;
};

struct BaselineFrame {
  int64_t t_ns = 0;
  CameraObservation left, right, mono;
  int n_stereo_lights = 0;  // triangulated and used in the SVD alignment
  int n_mono_lights = 0;    // used in the PnP
  VisibilityStage stage = VisibilityStage::kNeither;  // from what was usable
  std::optional<Pose3> T_D_B_stereo, T_D_B_mono;
  std::optional<Pose3> T_D_B;  // the fused (reported) pose
  double stereo_weight = 0.0;
  std::string reason;  // why there is no pose
};

class PaperBaselinePipeline {
 public:
  // The calibration must hold cameras with roles stereo_left, stereo_right and mono; a missing
  // one is simply never used (EuRoC has no mono camera).
  PaperBaselinePipeline(const Calibration& calibration, const DockModel& dock,
                        const PaperBaselineOptions& options = {});

  // Any image may be empty (camera absent or image unreadable).
  BaselineFrame Process(int64_t t_ns, const cv::Mat& left, const cv::Mat& right,
                        const cv::Mat& mono);

  const CameraCalibration* left_camera() const { return left_; }
  const CameraCalibration* right_camera() const { return right_; }
  const CameraCalibration* mono_camera() const { return mono_; }

 private:
  // Identifies the detections of one image against the dock; returns the matcher's pose.
  std::optional<Pose3> Identify(const CameraCalibration& camera, int64_t t_ns,
                                CameraObservation* obs);
  void StereoPose(BaselineFrame* frame);
  void MonoPose(const std::optional<Pose3>& T_C_D_initial, BaselineFrame* frame);

  Calibration calibration_;
  DockModel dock_;
  PaperBaselineOptions options_;
  LightDetector detector_;
  std::mt19937_64 rng_;
  std::optional<Pose3> last_T_D_B_;  // the previous reported pose, for tracking
  int64_t last_t_ns_ = 0;
  const CameraCalibration* left_ = nullptr;
  const CameraCalibration* right_ = nullptr;
  const CameraCalibration* mono_ = nullptr;
};

}  // namespace auvdock
