#include "auvdock/vision/paper_baseline_pipeline.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "auvdock/vision/given_identity_check.h"
#include "auvdock/vision/omnidirectional_matcher.h"
#include "auvdock/vision/pnp_solver.h"
#include "auvdock/vision/point_set_alignment.h"
#include "auvdock/vision/pose_verdict.h"

namespace auvdock {
namespace {

// The blob detector's options with the dock's light colour.
BlobLightDetectorOptions WithDockColour(BlobLightDetectorOptions options, const DockModel& dock) {
  options.checks.colour = ParseLightColour(dock.light_colour);
  return options;
}

BlobLightDetectorOptions WeakOptions(const PaperBaselineOptions& options, const DockModel& dock) {
  if (!(options.weak_min_response > 0.0) ||
      !(options.weak_halo_fraction >= 0.0 && options.weak_halo_fraction <= 1.0) ||
      !(options.weak_min_support >= 0.0 && options.weak_min_support <= 1.0) ||
      !(options.weak_min_view_elevation_deg >= 0.0 && options.weak_min_view_elevation_deg < 90.0)) {
    throw std::invalid_argument("PaperBaselineOptions: weak pass out of range");
  }
  BlobLightDetectorOptions weak = WithDockColour(options.blob_detector, dock);
  weak.candidates.min_response = std::min(weak.candidates.min_response, options.weak_min_response);
  return weak;
}

LearnedLightDetectorOptions WithDockColour(LearnedLightDetectorOptions options,
                                           const DockModel& dock) {
  options.colour = ParseLightColour(dock.light_colour);
  return options;
}

}  // namespace

int CameraObservation::num_identified() const {
  return static_cast<int>(
      std::count_if(light_ids.begin(), light_ids.end(), [](int id) { return id >= 0; }));
}

PaperBaselinePipeline::PaperBaselinePipeline(const Calibration& calibration, const DockModel& dock,
                                             const PaperBaselineOptions& options)
    : calibration_(calibration),
      dock_(dock),
      options_(options),
      dehazer_(options.dehaze_options),
      blob_detector_(WithDockColour(options.blob_detector, dock)),
      weak_detector_(WeakOptions(options, dock)),
      learned_detector_(options.detector_kind == LightDetectorKind::kLearned
                            ? std::make_shared<const LearnedLightDetector>(
                                  WithDockColour(options.learned_detector, dock))
                            : nullptr),
      guided_search_(WithDockColour(options.blob_detector, dock), options.guided),
      colour_learners_{HaloColourLearner(options.blob_detector.checks.min_halo_excess),
                       HaloColourLearner(options.blob_detector.checks.min_halo_excess),
                       HaloColourLearner(options.blob_detector.checks.min_halo_excess)},
      rng_(options.seed) {
  left_ = calibration_.FindCameraByRole(CameraRole::kStereoLeft);
  right_ = calibration_.FindCameraByRole(CameraRole::kStereoRight);
  mono_ = calibration_.FindCameraByRole(CameraRole::kMono);
  if ((left_ != nullptr) != (right_ != nullptr)) {
    const CameraCalibration* lone = left_ ? left_ : right_;
    warnings_.push_back("camera " + lone->name + " has role " +
                        (left_ ? "stereo_left" : "stereo_right") + " but the rig has no " +
                        (left_ ? "stereo_right" : "stereo_left") +
                        ": its images are not used (a single camera takes role mono)");
  }
  if (!left_ && !right_ && !mono_) {
    warnings_.push_back("no camera has role stereo_left, stereo_right or mono: no vision");
  }
}

std::optional<Pose3> PaperBaselinePipeline::Predict(const CameraCalibration& camera,
                                                    int64_t t_ns) const {
  const bool recent =
      last_T_D_B_ && static_cast<double>(t_ns - last_t_ns_) * 1e-9 <= options_.tracking_max_age_s;
  if (!options_.use_tracking) return std::nullopt;
  if (recent) return (*last_T_D_B_ * camera.T_B_C).Inverse();
  if (external_T_D_B_) return (*external_T_D_B_ * camera.T_B_C).Inverse();
  return std::nullopt;
}

std::optional<Pose3> PaperBaselinePipeline::Identify(const CameraCalibration& camera, int64_t t_ns,
                                                     const std::vector<int>& given_ids,
                                                     CameraObservation* obs) {
  obs->light_ids.assign(obs->detections.size(), -1);
  MatchResult match;
  std::optional<Pose3> T_C_D;
  const std::optional<Pose3> predicted_T_C_D = Predict(camera, t_ns);
  if (std::any_of(given_ids.begin(), given_ids.end(), [](int id) { return id >= 0; })) {
    GivenIdentityCheckOptions check_options;
    check_options.pixel_noise_px = camera.pixel_noise_px;
    const GivenIdentityCheck check = CheckGivenIdentities(
        obs->detections, given_ids, dock_, camera.intrinsics, check_options, predicted_T_C_D);
    obs->given_dropped = check.dropped;
    if (check.match.status == MatchStatus::kOk) {
      obs->given_used = true;
      obs->status = MatchStatus::kOk;
      obs->reason.clear();
      for (const LightMatch& m : check.match.matches) obs->light_ids[m.detection] = m.light_id;
      return check.T_C_D ? check.T_C_D : predicted_T_C_D;
    }
    obs->given_reason = check.match.reason;
  }
  if (options_.matcher == BaselineMatcher::kOmnidirectional) {
    match = MatchOmnidirectional(obs->detections, dock_);
  } else {
    RansacMatcherOptions ransac = options_.ransac;
    ransac.pixel_noise_px = camera.pixel_noise_px;
    // A symmetric dock's poses: the copy nearest the prediction, else the approach side.
    SymmetryHint hint;
    hint.predicted_T_C_D = predicted_T_C_D;
    if (dock_.approach_direction_D.norm() > 0.0) {
      hint.approach_direction_D = dock_.approach_direction_D;
    }
    if (fix_ && t_ns >= fix_->t_ns) {
      const double age_s = 1e-9 * static_cast<double>(t_ns - fix_->t_ns);
      if (age_s <= options_.fix_max_age_s) {
        hint.fix_p_D = fix_->p_D;
        hint.fix_sigma_m = std::hypot(fix_->sigma_m, options_.fix_max_speed_mps * age_s);
        hint.T_C_S = camera.T_B_C.Inverse() * fix_->T_B_S;
      }
    }
    RansacMatchResult result =
        MatchRansac(obs->detections, dock_, camera.intrinsics, ransac, rng_, hint);
    T_C_D = result.T_C_D;
    match = result;
    obs->symmetry = result.symmetry;
    obs->symmetry_unresolved = result.symmetry_unresolved;
    obs->symmetry_by_prediction = result.symmetry_by_prediction;
  }
  if (match.status != MatchStatus::kOk && predicted_T_C_D) {
    const MatchResult tracked = MatchByPrediction(obs->detections, dock_, camera.intrinsics,
                                                  *predicted_T_C_D, options_.tracking);
    if (tracked.status == MatchStatus::kOk) {
      match = tracked;
      T_C_D = predicted_T_C_D;
      obs->tracked = true;
    }
  }
  obs->status = match.status;
  obs->reason = match.reason;
  if (match.status == MatchStatus::kOk) {
    for (const LightMatch& m : match.matches) obs->light_ids[m.detection] = m.light_id;
  }
  return T_C_D;
}

void PaperBaselinePipeline::StereoPose(bool left_identified,
                                       const std::optional<Pose3>& T_I_D_identified,
                                       BaselineFrame* frame) {
  CameraObservation& identified = left_identified ? frame->left : frame->right;
  CameraObservation& partner = left_identified ? frame->right : frame->left;
  const CameraCalibration& identified_camera = left_identified ? *left_ : *right_;
  const CameraCalibration& partner_camera = left_identified ? *right_ : *left_;
  partner.light_ids.assign(partner.detections.size(), -1);

  // The partner image's own identification, by prediction from the identified camera's pose
  // through the rig's extrinsics. Left-right matching by position and radius alone can pair a
  // light with its neighbour when several lights share an epipolar line (the T's crossbar seen
  // nearly parallel to the baseline at long range: a shift by one light keeps the ordering and
  // gives a plausible, wrong depth); the prediction cannot, since the whole pattern must line up.
  std::vector<int> predicted_ids(partner.detections.size(), -1);
  bool partner_predicted = false;
  if (T_I_D_identified && identified.status == MatchStatus::kOk) {
    const Pose3 T_P_D =
        partner_camera.T_B_C.Inverse() * identified_camera.T_B_C * *T_I_D_identified;
    TrackingMatcherOptions tracking = options_.tracking;
    tracking.pixel_noise_px = partner_camera.pixel_noise_px;
    const MatchResult predicted =
        MatchByPrediction(partner.detections, dock_, partner_camera.intrinsics, T_P_D, tracking);
    if (predicted.status == MatchStatus::kOk) {
      partner_predicted = true;
      for (const LightMatch& m : predicted.matches) predicted_ids[m.detection] = m.light_id;
    }
  }

  // Stereo pairs (left, right): with the partner identified, the detections of the same light in
  // both images, kept if they meet on the epipolar line (triangulation residual within the
  // epipolar gate); otherwise the paper's left-right matching (MatchStereoDetections), the
  // identities flowing from the identified image to its partner.
  std::vector<std::pair<int, int>> pairs;
  if (partner_predicted) {
    for (std::size_t i = 0; i < identified.light_ids.size(); ++i) {
      if (identified.light_ids[i] < 0) continue;
      for (std::size_t p = 0; p < predicted_ids.size(); ++p) {
        if (predicted_ids[p] != identified.light_ids[i]) continue;
        pairs.emplace_back(left_identified ? static_cast<int>(i) : static_cast<int>(p),
                           left_identified ? static_cast<int>(p) : static_cast<int>(i));
      }
    }
  } else {
    pairs = MatchStereoDetections(frame->left.detections, frame->right.detections, *left_, *right_,
                                  options_.stereo);
  }
  std::vector<std::pair<int, int>> used;
  std::vector<Eigen::Vector3d> p_S, p_D;
  for (const auto& [l, r] : pairs) {
    const int i = left_identified ? l : r;
    const int p = left_identified ? r : l;
    const int id = identified.light_ids[i];
    if (id < 0) continue;
    const TriangulatedPoint point =
        TriangulateLinear(frame->left.detections[l].uv, frame->right.detections[r].uv, *left_,
                          *right_, left_->pixel_noise_px);
    if (!point.ok) continue;
    if (partner_predicted && point.reprojection_rms_px > options_.stereo.epipolar_gate_px) continue;
    partner.light_ids[p] = id;
    used.emplace_back(l, r);
    p_S.push_back(point.p_S);
    p_D.push_back(dock_.FindLight(id)->p_D);
  }
  if (static_cast<int>(p_S.size()) < options_.min_stereo_lights) return;
  const AlignmentResult aligned = AlignPointSets(p_S, p_D);  // the paper's unweighted SVD
  if (!aligned.ok) {
    frame->reason = "stereo: " + aligned.reason;
    return;
  }
  // The aligned pose must put every used light back onto its detection in both images: a wrong
  // identity cannot be aligned rigidly with the others and shows up here. Refuse rather than
  // report a wrong pose. Identities transferred by left-right matching are withdrawn (the
  // estimator reads them); identities the partner image got from its own prediction-gated match
  // stay: they were checked against the whole pattern in that image, and an SVD pose that
  // misses by a few pixels at long range says more about the triangulated depths than about them.
  const Pose3 T_L_D = aligned.T_dst_src.Inverse();
  const Pose3 T_R_D = right_->T_B_C.Inverse() * left_->T_B_C * T_L_D;
  double worst_px = 0.0;
  for (std::size_t k = 0; k < used.size(); ++k) {
    const auto uv_l = left_->intrinsics.Project(T_L_D * p_D[k]);
    const auto uv_r = right_->intrinsics.Project(T_R_D * p_D[k]);
    if (!uv_l || !uv_r) {
      worst_px = std::numeric_limits<double>::infinity();
      break;
    }
    worst_px = std::max({worst_px, (*uv_l - frame->left.detections[used[k].first].uv).norm(),
                         (*uv_r - frame->right.detections[used[k].second].uv).norm()});
  }
  if (!(worst_px <= options_.max_stereo_reprojection_px)) {
    if (!partner_predicted) partner.light_ids.assign(partner.detections.size(), -1);
    frame->reason = "stereo: the aligned pose reprojects " + std::to_string(worst_px) +
                    " px from a light (identities inconsistent)";
    return;
  }
  frame->stereo_reprojection_px = worst_px;
  frame->n_stereo_lights = static_cast<int>(p_S.size());
  frame->T_D_B_stereo = aligned.T_dst_src * left_->T_B_C.Inverse();
}

void PaperBaselinePipeline::MonoPose(const std::optional<Pose3>& predicted_T_C_D,
                                     BaselineFrame* frame) {
  // Every light weighed alike, except one whose detection claims far more than the typical
  // sigma of the identified ones (PixelCovarianceForPose; a detector that measures no
  // covariance: the camera's pixel noise for all).
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<LightDetection> identified;
  for (std::size_t i = 0; i < frame->mono.detections.size(); ++i) {
    const int id = frame->mono.light_ids[i];
    if (id < 0) continue;
    points.push_back(dock_.FindLight(id)->p_D);
    pixels.push_back(frame->mono.detections[i].uv);
    identified.push_back(frame->mono.detections[i]);
  }
  const double typical_sigma = TypicalPixelSigma(identified, mono_->pixel_noise_px);
  std::vector<Eigen::Matrix2d> covariances;
  for (const LightDetection& d : identified) {
    covariances.push_back(PixelCovarianceForPose(d, typical_sigma));
  }
  const int needed =
      frame->mono.tracked ? std::min(3, options_.min_mono_lights) : options_.min_mono_lights;
  if (static_cast<int>(points.size()) < needed) return;
  PnpOptions pnp;
  pnp.pixel_sigma = mono_->pixel_noise_px;
  // The prediction, not the matcher's pose: of a planar target's two minima that fit the pixels
  // equally well the matcher keeps the lower cost, which is no evidence; only a pose known
  // independently of this image can choose (SolvePnp step 2b), else there is no mono pose.
  const PnpResult result =
      SolvePnp(points, pixels, mono_->intrinsics, pnp, predicted_T_C_D, covariances);
  if (!result.ok) {
    frame->reason = "mono: " + result.reason;
    return;
  }
  frame->n_mono_lights = static_cast<int>(points.size());
  frame->T_D_B_mono = result.T_C_D.Inverse() * mono_->T_B_C.Inverse();
}

BaselineFrame PaperBaselinePipeline::Process(int64_t t_ns, const cv::Mat& left_image,
                                             const cv::Mat& right_image,
                                             const cv::Mat& mono_image,
                                             const std::optional<Pose3>& predicted_T_D_B) {
  // Every step below sees the dehazed images when dehazing is on.
  auto dehazed = [&](const cv::Mat& image) {
    return options_.dehaze && !image.empty() ? dehazer_.Dehaze(image).image : image;
  };
  const cv::Mat left = dehazed(left_image);
  const cv::Mat right = dehazed(right_image);
  const cv::Mat mono = dehazed(mono_image);
  auto detect = [&](const CameraCalibration* camera, const cv::Mat& image, int index) {
    std::optional<std::vector<LightDetection>> detections;
    if (!camera || image.empty()) return detections;
    if (options_.detector_kind == LightDetectorKind::kLearned) {
      detections = learned_detector_->Detect(image);
    } else {
      detections = blob_detector_.Detect(image, nullptr, colour_learners_[index].threshold());
    }
    return detections;
  };
  BaselineFrame frame = ProcessDetections(t_ns, detect(left_, left, 0), detect(right_, right, 1),
                                          detect(mono_, mono, 2), predicted_T_D_B);
  if (!frame.T_D_B && options_.weak_pass) {
    frame = WeakPass(std::move(frame), left, right, mono, predicted_T_D_B);
  }
  colour_learners_[0].Observe(frame.left.detections, frame.left.light_ids);
  colour_learners_[1].Observe(frame.right.detections, frame.right.light_ids);
  colour_learners_[2].Observe(frame.mono.detections, frame.mono.light_ids);
  const std::array<std::pair<const CameraCalibration*, const cv::Mat*>, 3> cameras = {
      std::make_pair(left_, &left), std::make_pair(right_, &right), std::make_pair(mono_, &mono)};
  std::array<CameraObservation*, 3> observations = {&frame.left, &frame.right, &frame.mono};
  if (options_.guided_search && frame.T_D_B) {
    for (int c = 0; c < 3; ++c) {
      const auto [camera, image] = cameras[c];
      if (!camera || image->empty()) continue;
      CameraObservation& obs = *observations[c];
      obs.guided =
          SearchMissedLights(guided_search_, *image, dock_, camera->intrinsics,
                             (*frame.T_D_B * camera->T_B_C).Inverse(),
                             Eigen::Matrix<double, 6, 6>::Zero(), options_.guided_pose_sigma_px,
                             colour_learners_[c].threshold(), &obs.detections, &obs.light_ids);
    }
  }
  // 7 (the search): where the estimate puts the lights of the cameras it identified.
  if (frame.by_estimate && options_.guided_search) {
    for (int c = 0; c < 3; ++c) {
      const auto [camera, image] = cameras[c];
      CameraObservation& obs = *observations[c];
      if (!camera || image->empty() || obs.status == MatchStatus::kOk) continue;
      const Pose3 T_C_D = (*predicted_T_D_B * camera->T_B_C).Inverse();
      const size_t first = obs.detections.size();
      const int found =
          SearchMissedLights(guided_search_, *image, dock_, camera->intrinsics, T_C_D,
                             Eigen::Matrix<double, 6, 6>::Zero(), options_.estimate_sigma_px,
                             colour_learners_[c].threshold(), &obs.detections, &obs.light_ids);
      obs.guided += found;
      obs.by_estimate += WeighEstimateLabels(*camera, T_C_D, first, &obs);
    }
    NoteIdentified(frame);
  }
  return frame;
}

BaselineFrame PaperBaselinePipeline::ProcessDetections(
    int64_t t_ns, const std::optional<std::vector<LightDetection>>& left,
    const std::optional<std::vector<LightDetection>>& right,
    const std::optional<std::vector<LightDetection>>& mono,
    const std::optional<Pose3>& predicted_T_D_B, const GivenIdentities& given) {
  external_T_D_B_ = predicted_T_D_B;
  BaselineFrame frame;
  frame.t_ns = t_ns;
  const bool have_stereo = left_ && right_ && left && right;
  const bool have_mono = mono_ && mono;
  if (have_stereo) {
    frame.left.detections = *left;
    frame.right.detections = *right;
    std::optional<Pose3> T_C_D = Identify(*left_, t_ns, given.left, &frame.left);
    const bool left_identified = frame.left.status == MatchStatus::kOk;
    if (!left_identified) {
      T_C_D = Identify(*right_, t_ns, given.right, &frame.right);
    } else {
      frame.right.status = MatchStatus::kOk;
    }
    StereoPose(left_identified, T_C_D, &frame);
  }
  if (have_mono) {
    frame.mono.detections = *mono;
    Identify(*mono_, t_ns, given.mono, &frame.mono);
    if (frame.mono.status == MatchStatus::kOk) MonoPose(Predict(*mono_, t_ns), &frame);
  }

  const bool stereo = frame.T_D_B_stereo.has_value();
  const bool mono_ok = frame.T_D_B_mono.has_value();
  if (stereo && mono_ok) {
    frame.stage = VisibilityStage::kBoth;
    frame.stereo_weight =
        static_cast<double>(frame.n_stereo_lights) / (frame.n_stereo_lights + frame.n_mono_lights);
    frame.T_D_B = Interpolate(*frame.T_D_B_mono, *frame.T_D_B_stereo, frame.stereo_weight);
  } else if (stereo) {
    frame.stage = VisibilityStage::kStereoOnly;
    frame.stereo_weight = 1.0;
    frame.T_D_B = frame.T_D_B_stereo;
  } else if (mono_ok) {
    frame.stage = VisibilityStage::kMonoOnly;
    frame.T_D_B = frame.T_D_B_mono;
  } else {
    frame.stage = VisibilityStage::kNeither;
    if (frame.reason.empty()) frame.reason = "no camera sees enough identified lights";
  }
  if (frame.T_D_B) {
    // Symmetry provenance of the track: an unresolved choice in any camera taints it; a choice
    // by evidence of its own (gravity, a fix, the approach side: not the prediction, which
    // follows the track) clears it; tracking and the prediction keep it as it was.
    bool unresolved = false, resolved = false;
    for (const CameraObservation* obs : {&frame.left, &frame.right, &frame.mono}) {
      if (obs->status != MatchStatus::kOk || obs->symmetry.empty() || obs->tracked) continue;
      if (obs->symmetry_unresolved) {
        unresolved = true;
      } else if (!obs->symmetry_by_prediction) {
        resolved = true;
      }
    }
    const bool continues = last_T_D_B_ && t_ns - last_t_ns_ <= static_cast<int64_t>(
                                              1e9 * options_.tracking_max_age_s);
    if (unresolved) {
      track_symmetry_unresolved_ = true;
    } else if (resolved || (!continues && !predicted_T_D_B)) {
      track_symmetry_unresolved_ = false;
    }
    frame.symmetry_unresolved = track_symmetry_unresolved_;
    last_T_D_B_ = frame.T_D_B;
    last_t_ns_ = t_ns;
  }
  // 7. Without a pose: the few lights of each camera that identified none, by the estimate.
  const bool estimate_is_fresh =
      last_identified_t_ns_ &&
      static_cast<double>(t_ns - *last_identified_t_ns_) * 1e-9 <= options_.estimate_max_age_s;
  if (options_.identify_by_estimate && !frame.T_D_B && predicted_T_D_B && estimate_is_fresh) {
    frame.by_estimate = true;
    const std::array<std::pair<const CameraCalibration*, CameraObservation*>, 3> cameras = {
        std::make_pair(left_, &frame.left), std::make_pair(right_, &frame.right),
        std::make_pair(mono_, &frame.mono)};
    for (const auto& [camera, obs] : cameras) {
      if (!camera || obs->status == MatchStatus::kOk || obs->detections.empty()) continue;
      obs->light_ids = AssociateByPrediction(
          obs->detections,
          PredictLights(dock_, camera->intrinsics, (*predicted_T_D_B * camera->T_B_C).Inverse(),
                        Eigen::Matrix<double, 6, 6>::Zero(), {}),
          options_.estimate_association);
      obs->by_estimate =
          WeighEstimateLabels(*camera, (*predicted_T_D_B * camera->T_B_C).Inverse(), 0, obs);
    }
  }
  NoteIdentified(frame);
  return frame;
}

BaselineFrame PaperBaselinePipeline::WeakPass(BaselineFrame frame, const cv::Mat& left,
                                              const cv::Mat& right, const cv::Mat& mono,
                                              const std::optional<Pose3>& predicted_T_D_B) {
  bool more = false;
  auto weak = [&](const CameraCalibration* camera, const cv::Mat& image, int index,
                  const CameraObservation& first) {
    std::optional<std::vector<LightDetection>> detections;
    if (!camera || image.empty()) return detections;
    detections = weak_detector_.Detect(image, nullptr,
                                       options_.weak_halo_fraction * colour_learners_[index].threshold());
    // The strongest few only: hypothesise-and-verify over many weak blobs costs more than the
    // rest of the frame, and clutter can fit a layout.
    const size_t most = dock_.lights.size() + 4;
    if (detections->size() > most) detections->resize(most);
    more = more || detections->size() > first.detections.size();
    return detections;
  };
  const auto weak_left = weak(left_, left, 0, frame.left);
  const auto weak_right = weak(right_, right, 1, frame.right);
  const auto weak_mono = weak(mono_, mono, 2, frame.mono);
  if (!more) return frame;
  const auto last_T_D_B = last_T_D_B_;
  const int64_t last_t_ns = last_t_ns_;
  const bool track_symmetry_unresolved = track_symmetry_unresolved_;
  const auto last_identified_t_ns = last_identified_t_ns_;
  BaselineFrame retry =
      ProcessDetections(frame.t_ns, weak_left, weak_right, weak_mono, predicted_T_D_B);
  RansacMatcherOptions view = options_.ransac;
  view.min_view_elevation_deg =
      std::max(view.min_view_elevation_deg, options_.weak_min_view_elevation_deg);
  const std::array<std::pair<const CameraCalibration*, const CameraObservation*>, 3> cameras = {
      std::make_pair(left_, &retry.left), std::make_pair(right_, &retry.right),
      std::make_pair(mono_, &retry.mono)};
  bool explains_most = retry.T_D_B.has_value();
  for (const auto& [camera, obs] : cameras) {
    if (!explains_most) break;
    if (!camera || obs->status != MatchStatus::kOk) continue;
    explains_most = ExplainsMostOfItsView(dock_, camera->intrinsics,
                                          (*retry.T_D_B * camera->T_B_C).Inverse(),
                                          obs->num_identified(), options_.weak_min_support, view);
  }
  if (explains_most) return retry;
  last_T_D_B_ = last_T_D_B;
  last_t_ns_ = last_t_ns;
  track_symmetry_unresolved_ = track_symmetry_unresolved;
  last_identified_t_ns_ = last_identified_t_ns;
  return frame;
}

void PaperBaselinePipeline::SetPositionFix(int64_t t_ns, const Eigen::Vector3d& p_D,
                                           double sigma_m, const Pose3& T_B_S) {
  if (!p_D.allFinite() || !std::isfinite(sigma_m) || !(sigma_m > 0.0)) return;
  if (fix_ && t_ns <= fix_->t_ns) return;  // a late fix overtaken by a newer one
  fix_ = PositionFix{t_ns, p_D, sigma_m, T_B_S};
}

int PaperBaselinePipeline::WeighEstimateLabels(const CameraCalibration& camera, const Pose3& T_C_D,
                                               size_t first, CameraObservation* obs) const {
  const std::vector<PredictedLight> predicted =
      PredictLights(dock_, camera.intrinsics, T_C_D, Eigen::Matrix<double, 6, 6>::Zero(), {});
  int kept = 0;
  for (size_t i = first; i < obs->detections.size(); ++i) {
    const int id = obs->light_ids[i];
    if (id < 0) continue;
    LightDetection& d = obs->detections[i];
    const double isolation = options_.estimate_association.isolation_radii * d.radius_px;
    const bool merged =
        std::any_of(predicted.begin(), predicted.end(), [&](const PredictedLight& p) {
          return p.light_id != id && (p.uv - d.uv).norm() < isolation;
        });
    if (merged) {
      obs->light_ids[i] = -1;
      continue;
    }
    const double s = options_.estimate_size_sigma_fraction * d.radius_px;
    d.covariance += s * s * Eigen::Matrix2d::Identity();
    ++kept;
  }
  return kept;
}

void PaperBaselinePipeline::NoteIdentified(const BaselineFrame& frame) {
  if (frame.left.num_identified() + frame.right.num_identified() + frame.mono.num_identified() >
      0) {
    last_identified_t_ns_ = frame.t_ns;
  }
}

}  // namespace auvdock
