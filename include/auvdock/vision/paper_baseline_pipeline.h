// The source paper's per-frame pose pipeline, end to end (seed 000, sections 2-3; seed 004's
// stereo-to-mono handoff), kept as the baseline the estimator has to beat and as its source of
// initial values.
//
// Per frame (three synchronized images: stereo left, stereo right, mono):
//   1. detect guide lights in every image (the real-water BlobLightDetector, or the learned
//      detector; optional dark-channel dehazing first, seed 000);
//   2. identify them: the left (else right) stereo image and the mono image are matched to the
//      dock model by hypothesise-and-verify (MatchRansac; the paper's omnidirectional matcher is
//      selectable), the other stereo image inherits the identities through left-right matching
//      on the epipolar line (MatchStereoDetections, seed 004), checked against its own
//      identification by prediction from the identified camera's pose (MatchByPrediction through
//      the rig's extrinsics): a pair is used only when both give the same light. Identities
//      given with the detections (ProcessDetections' GivenIdentities: a front-end of the
//      user's) replace the matcher for an image when they fit the dock (CheckGivenIdentities);
//   3. stereo pose: triangulate the identified pairs (TriangulateLinear, eqs. 11-16) in the left
//      camera frame S and align them to the dock lights by SVD (AlignPointSets, eqs. 17-23):
//      T_D_S, then T_D_B = T_D_S T_B_S^-1 (S is cam0). The aligned pose is kept only if it
//      reprojects every used light within max_stereo_reprojection_px of its detection in both
//      images; otherwise there is no stereo pose and the partner's identities are withdrawn.
//      Why: at 8-10 m the T's crossbar lies nearly along an epipolar line, and left-right
//      matching by position and radius alone paired lights 4 and 5 of the left image with the
//      detections of lights 3 and 4 of the right one (shift by one light: the ordering holds and
//      the depth, ~3 m instead of ~9 m, passes the depth gate); the SVD then aligned the wrong
//      points into a pose 9-10 m off (default scenario, t = 6.0-6.1 s, with the detector's
//      radii inflated by the lit deck);
//   4. mono pose: PnP by Levenberg-Marquardt (SolvePnp, eq. 10): T_C_D, then
//      T_D_B = T_C_D^-1 T_B_C^-1. When two poses fit the lights about equally well (a planar
//      target's two-fold ambiguity, SolvePnp step 2b) the prediction from the previous reported
//      pose chooses, if recent and clearly nearer one of them; otherwise there is no mono pose
//      and the reason says "ambiguous". Why: at t = 27.5 s of the default scenario the mono
//      camera sees the stem (lights 1, 2, 4, collinear) and light 3 from 2.5 m; the flipped
//      minimum (21 deg of roll, 0.9 m across the dock away) fitted 0.1 px^2 better than the true
//      one and was reported. The matcher's own pose is no tie-breaker: it kept the lower cost;
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
//   5b. weak pass (weak_pass): a frame without a pose is detected once more
//      with the blob detector at a laxer response and halo colour (weak_min_response,
//      weak_halo_fraction; its strongest blobs only, 4 more than the dock has lights per image)
//      and steps 2-5 run again on those detections. Its pose is taken only if every camera it
//      identified identifies at least weak_min_support of the lights that pose puts in its
//      image, and sees the deck from weak_min_view_elevation_deg above its plane or more (as
//      `detect`'s weak pass, mono_light_pipeline.h); otherwise the frame stays as it was. Why:
//      the far, dim lights of an approach's first seconds (default scenario: the real-water
//      detector's full pass found 0-4 of the T dock's lights in the first 4 s, the run started
//      38 frames late);
//   6. second look (guided_search): with the fused pose of step 5, each camera's dock
//      lights that it projects where no detection is are searched for in that image
//      (GuidedLightSearch, each prediction's covariance guided_pose_sigma_px^2 I, its size
//      scaled by the identified lights' ObservedSizeRatio) and added
//      with their identity (CameraObservation::guided); the frame's poses are not re-solved
//      (the estimator fuses the added lights).
//   7. identification by the estimate (identify_by_estimate): in a frame without a pose, each
//      camera that identified no light labels its detections by the prediction from elsewhere
//      (the estimator's IMU propagation, predicted_T_D_B) alone (AssociateByPrediction,
//      prediction_association.h: a unique light within a few pixels; ProcessDetections does
//      this) and, in Process with guided_search, searches where the prediction puts
//      its lights
//      (estimate_sigma_px; scales up to 4x the expected size, for the large glows of a light
//      under the camera). Only while the prediction is fresh: some camera identified lights
//      within estimate_max_age_s before (so the estimator has been corrected by vision since).
//      This is what keeps the vision in the last seconds of a landing, when each camera sees
//      one or two lights and no per-frame pose exists; wrong labels meet the estimator's
//      chi-square gate. Unverified by any pattern, these labels carry a centroid covariance that
//      grows with the blob (+ (estimate_size_sigma_fraction r)^2): the centre of a light that
//      fills a large part of the image, saturated or merged with its neighbours' glow, is not
//      known to a fraction of a pixel (on our randomised renders a saturated disc's centroid is
//      off by 0.1 of its radius up to 30 px, 0.2-0.3 beyond). The observations say how many of
//      their labels came from here (CameraObservation::by_estimate).
// Frames: D dock (z down), B body, C camera (OpenCV). Units: metres, radians, pixels.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "auvdock/geometry/dock_model.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"
#include "auvdock/vision/blob_light_detector.h"
#include "auvdock/vision/learned_light_detector.h"
#include "auvdock/vision/guided_light_search.h"
#include "auvdock/vision/halo_colour_learner.h"
#include "auvdock/vision/dark_channel_dehazer.h"
#include "auvdock/vision/prediction_association.h"
#include "auvdock/vision/ransac_matcher.h"
#include "auvdock/vision/stereo_triangulation.h"
#include "auvdock/vision/tracking_matcher.h"

namespace auvdock {

enum class BaselineMatcher { kRansac, kOmnidirectional };

// kBlob: the real-water BlobLightDetector (blob_light_detector.h) with a halo colour learned per
// camera from the identified lights (halo_colour_learner.h); kLearned: the network learned from
// randomised renders (learned_light_detector.h; its model file in learned_detector.model_path),
// with the same learned halo colour, weak pass, second look and search by the estimate. (The
// detector developed on our own renders, light_detector.h, was removed on 2026-12-07: on the real
// pool clip and on the randomised renders it measured worse than the real-water detector, and it
// was preferred only on the un-randomised renders it was tuned to; docs/light_detectors.md.)
enum class LightDetectorKind { kBlob, kLearned };

struct PaperBaselineOptions {
  LightDetectorKind detector_kind = LightDetectorKind::kBlob;
  // Dark-channel dehazing of every image before detection (seed 000). Off by default: it rescales
  // the lights' contrast and the noise by the same gain (it adds no signal) and makes halos.
  bool dehaze = false;
  DehazeOptions dehaze_options;  // seed 000: omega 0.5
  BlobLightDetectorOptions blob_detector;
  LearnedLightDetectorOptions learned_detector;  // kLearned only (its colour: the dock's)
  BaselineMatcher matcher = BaselineMatcher::kRansac;
  RansacMatcherOptions ransac;
  StereoMatchOptions stereo;
  int min_stereo_lights = 3;  // triangulated, non-collinear
  // Largest distance (px) between a used light's detection and its reprojection with the aligned
  // stereo pose, in either image. Correct identities stay within 2.6 px (95 % within 1.4 px) on
  // the default scenario (depth noise at 9 m); one swapped identity moves lights tens of pixels.
  double max_stereo_reprojection_px = 4.0;
  int min_mono_lights = 4;    // a unique PnP (3 when tracking supplies the initial pose)
  bool use_tracking = true;
  double tracking_max_age_s = 0.5;  // a previous pose older than this predicts nothing
  TrackingMatcherOptions tracking;
  bool weak_pass = true;  // step 5b
  double weak_min_response = 12.0;
  double weak_halo_fraction = 0.3;
  double weak_min_support = 0.75;
  double weak_min_view_elevation_deg = 10.0;
  bool guided_search = true;          // step 6
  GuidedLightSearchOptions guided;
  double guided_pose_sigma_px = 1.5;  // the fused per-frame pose's error at a light, 1 sigma
  bool identify_by_estimate = true;   // step 7
  PredictionAssociationOptions estimate_association;
  double estimate_sigma_px = 2.0;     // the estimate's error at a light, 1 sigma (step 7's search)
  double estimate_max_age_s = 0.5;    // step 7 only within this of the last identified light
  // Step 7's labels: each detection's centroid covariance grows by (this x its radius)^2.
  double estimate_size_sigma_fraction = 0.1;
  uint64_t seed = 1;          // the matcher's random subsets (deterministic)
  // A position fix (SetPositionFix) chooses among a symmetric dock's poses up to this age; its
  // sigma grows by max_speed_mps per second of age.
  double fix_max_age_s = 5.0;
  double fix_max_speed_mps = 1.0;
};

// What one camera saw and how its lights were identified.
struct CameraObservation {
  std::vector<LightDetection> detections;
  std::vector<int> light_ids;  // per detection: dock light id, or -1 when not identified
  MatchStatus status = MatchStatus::kFailed;
  std::string reason;
  std::string symmetry;  // how a symmetric dock's pose was chosen (empty: not symmetric)
  bool symmetry_unresolved = false;  // ... by nothing: the pose is one of the rival poses
  bool symmetry_by_prediction = false;  // ... by the prediction (it follows the track)
  bool tracked = false;  // identified by prediction (tracking) rather than from scratch
  int guided = 0;        // detections added by the second look (steps 6, 7), at the end
  int by_estimate = 0;   // lights identified by the estimate alone (step 7)
  // Identities given with the detections (GivenIdentities): used (they fit the dock), and how
  // many claims were left out; or why they were not used (then the image was identified here).
  bool given_used = false;
  int given_dropped = 0;
  std::string given_reason;
  int num_identified() const;
};

// Identities that a front-end reported with its detections (detections.csv's light_id), per
// camera and aligned with that camera's detections: the dock light id, or -1. Empty: none given.
// They are checked against the dock (CheckGivenIdentities) and, if they fit, replace step 2's
// identification of that image; otherwise the image is identified as usual. A symmetric dock's
// given identities are taken as they are: the front-end has chosen among its rival poses.
struct GivenIdentities {
  std::vector<int> left, right, mono;
};

struct BaselineFrame {
  int64_t t_ns = 0;
  CameraObservation left, right, mono;
  int n_stereo_lights = 0;  // triangulated and used in the SVD alignment
  int n_mono_lights = 0;    // used in the PnP
  double stereo_reprojection_px = 0.0;  // worst reprojection of the accepted stereo pose
  VisibilityStage stage = VisibilityStage::kNeither;  // from what was usable
  std::optional<Pose3> T_D_B_stereo, T_D_B_mono;
  std::optional<Pose3> T_D_B;  // the fused (reported) pose
  double stereo_weight = 0.0;
  std::string reason;  // why there is no pose
  bool by_estimate = false;  // step 7 ran: cameras that identified nothing used the estimate
  // The pose is one of a symmetric dock's rival poses, chosen by nothing: in this frame, or in
  // an earlier one that the track (the prediction) has followed since.
  bool symmetry_unresolved = false;
};

class PaperBaselinePipeline {
 public:
  // The calibration must hold cameras with roles stereo_left, stereo_right and mono; a missing
  // one is simply never used (EuRoC has no mono camera).
  PaperBaselinePipeline(const Calibration& calibration, const DockModel& dock,
                        const PaperBaselineOptions& options = {});

  // Any image may be empty (camera absent or image unreadable). predicted_T_D_B: the body pose
  // at t_ns known from elsewhere (the estimator's IMU propagation), used for tracking and for
  // choosing among a symmetric dock's poses when the pipeline's own last pose is too old.
  BaselineFrame Process(int64_t t_ns, const cv::Mat& left, const cv::Mat& right,
                        const cv::Mat& mono,
                        const std::optional<Pose3>& predicted_T_D_B = std::nullopt);

  // Steps 2-5 on detections made elsewhere (Process = the detector on each image, then
  // this); std::nullopt for an absent camera or image. given: identities reported with them.
  BaselineFrame ProcessDetections(int64_t t_ns,
                                  const std::optional<std::vector<LightDetection>>& left,
                                  const std::optional<std::vector<LightDetection>>& right,
                                  const std::optional<std::vector<LightDetection>>& mono,
                                  const std::optional<Pose3>& predicted_T_D_B = std::nullopt,
                                  const GivenIdentities& given = {});

  const CameraCalibration* left_camera() const { return left_; }
  const CameraCalibration* right_camera() const { return right_; }
  const CameraCalibration* mono_camera() const { return mono_; }
  // A position fix of a point of the vehicle (frame T_B_S; an acoustic USBL fix, 1-sigma
  // sigma_m per axis) at t_ns, used by the frames after it to choose among a symmetric dock's
  // poses (SymmetryHint::fix_p_D).
  void SetPositionFix(int64_t t_ns, const Eigen::Vector3d& p_D, double sigma_m,
                      const Pose3& T_B_S);

  // What of the rig the pipeline cannot use, and why (a lone stereo camera), for the log.
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  // Identifies the detections of one image against the dock, by the given identities when they
  // fit it, else by the matcher; returns the pose of the identification.
  std::optional<Pose3> Identify(const CameraCalibration& camera, int64_t t_ns,
                                const std::vector<int>& given_ids, CameraObservation* obs);
  // T_I_D_identified: the pose of the identified stereo camera (left if left_identified).
  void StereoPose(bool left_identified, const std::optional<Pose3>& T_I_D_identified,
                  BaselineFrame* frame);
  // predicted_T_C_D: from the previous reported pose (Predict), the PnP's start and tie-breaker.
  void MonoPose(const std::optional<Pose3>& predicted_T_C_D, BaselineFrame* frame);
  // T_C_D of `camera` predicted from the previous reported pose, if tracking is on and that pose
  // is at most tracking_max_age_s old.
  std::optional<Pose3> Predict(const CameraCalibration& camera, int64_t t_ns) const;
  // Step 7's labels from detection `first` on: withdrawn where another predicted light lies
  // within isolation_radii blob radii (merged glows), else their covariance grown with the
  // blob's size; returns how many stay.
  int WeighEstimateLabels(const CameraCalibration& camera, const Pose3& T_C_D, size_t first,
                          CameraObservation* obs) const;
  // Step 5b: the frame again from the weak detector's detections; the frame itself when its
  // pose does not explain most of the lights it puts in view (the tracking state then as before).
  BaselineFrame WeakPass(BaselineFrame frame, const cv::Mat& left, const cv::Mat& right,
                         const cv::Mat& mono, const std::optional<Pose3>& predicted_T_D_B);
  // Remembers the frame's time if any camera identified a light in it (step 7's freshness).
  void NoteIdentified(const BaselineFrame& frame);

  Calibration calibration_;
  DockModel dock_;
  PaperBaselineOptions options_;
  DarkChannelDehazer dehazer_;
  BlobLightDetector blob_detector_;
  BlobLightDetector weak_detector_;
  std::shared_ptr<const LearnedLightDetector> learned_detector_;  // kLearned only
  GuidedLightSearch guided_search_;
  std::array<HaloColourLearner, 3> colour_learners_;  // left, right, mono
  std::mt19937_64 rng_;
  std::optional<Pose3> last_T_D_B_;  // the previous reported pose, for tracking
  std::optional<Pose3> external_T_D_B_;  // this frame's prediction from elsewhere, if any
  struct PositionFix {
    int64_t t_ns = 0;
    Eigen::Vector3d p_D;
    double sigma_m = 0.0;
    Pose3 T_B_S;
  };
  std::optional<PositionFix> fix_;
  bool track_symmetry_unresolved_ = false;  // the reported track follows an unresolved choice
  int64_t last_t_ns_ = 0;
  std::optional<int64_t> last_identified_t_ns_;  // the last frame with an identified light
  const CameraCalibration* left_ = nullptr;
  const CameraCalibration* right_ = nullptr;
  const CameraCalibration* mono_ = nullptr;
  std::vector<std::string> warnings_;
};

}  // namespace auvdock
