#include "auvdock/vision/paper_baseline_pipeline.h"

#include <algorithm>

#include "auvdock/vision/omnidirectional_matcher.h"
#include "auvdock/vision/pnp_solver.h"
#include "auvdock/vision/point_set_alignment.h"

namespace auvdock {

int CameraObservation::num_identified() const {
  return static_cast<int>(std::count_if(light_ids.begin(), light_ids.end(),
                                        [](int id) { return id >= 0; }));
}

PaperBaselinePipeline::PaperBaselinePipeline(const Calibration& calibration,
                                             const DockModel& dock,
                                             const PaperBaselineOptions& options)
    : calibration_(calibration), dock_(dock), options_(options), detector_(options.detector),
      rng_(options.seed) {
  left_ = calibration_.FindCameraByRole(CameraRole::kStereoLeft);
  right_ = calibration_.FindCameraByRole(CameraRole::kStereoRight);
  mono_ = calibration_.FindCameraByRole(CameraRole::kMono);
}

std::optional<Pose3> PaperBaselinePipeline::Identify(const CameraCalibration& camera,
                                                     int64_t t_ns, CameraObservation* obs) {
  obs->light_ids.assign(obs->detections.size(), -1);
  MatchResult match;
  std::optional<Pose3> T_C_D;
  if (options_.matcher == BaselineMatcher::kOmnidirectional) {
    match = MatchOmnidirectional(obs->detections, dock_);
  } else {
    RansacMatcherOptions ransac = options_.ransac;
    ransac.pixel_noise_px = camera.pixel_noise_px;
    RansacMatchResult result = MatchRansac(obs->detections, dock_, camera.intrinsics, ransac, rng_);
    T_C_D = result.T_C_D;
    match = result;
  }
  const bool recent = last_T_D_B_ && static_cast<double>(t_ns - last_t_ns_) * 1e-9 <=
                                         options_.tracking_max_age_s;
  if (match.status != MatchStatus::kOk && options_.use_tracking && recent) {
    const Pose3 predicted_T_C_D = (*last_T_D_B_ * camera.T_B_C).Inverse();
    const MatchResult tracked = MatchByPrediction(obs->detections, dock_, camera.intrinsics,
                                                  predicted_T_C_D, options_.tracking);
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

void PaperBaselinePipeline::StereoPose(BaselineFrame* frame) {
  const auto pairs = MatchStereoDetections(frame->left.detections, frame->right.detections, *left_,
                                           *right_, options_.stereo);
  // Identities flow from the identified image to its partner.
  for (const auto& [l, r] : pairs) {
    int& id_left = frame->left.light_ids[l];
    int& id_right = frame->right.light_ids[r];
    if (id_left < 0) id_left = id_right;
    if (id_right < 0) id_right = id_left;
  }
  std::vector<Eigen::Vector3d> p_S, p_D;
  for (const auto& [l, r] : pairs) {
    const int id = frame->left.light_ids[l];
    if (id < 0 || id != frame->right.light_ids[r]) continue;
    const TriangulatedPoint point =
        TriangulateLinear(frame->left.detections[l].uv, frame->right.detections[r].uv, *left_,
                          *right_, left_->pixel_noise_px);
    if (!point.ok) continue;
    p_S.push_back(point.p_S);
    p_D.push_back(dock_.FindLight(id)->p_D);
  }
  if (static_cast<int>(p_S.size()) < options_.min_stereo_lights) return;
  const AlignmentResult aligned = AlignPointSets(p_S, p_D);  // the paper's unweighted SVD
  if (!aligned.ok) {
    frame->reason = "stereo: " + aligned.reason;
    return;
  }
  frame->n_stereo_lights = static_cast<int>(p_S.size());
  frame->T_D_B_stereo = aligned.T_dst_src * left_->T_B_C.Inverse();
}

void PaperBaselinePipeline::MonoPose(const std::optional<Pose3>& T_C_D_initial,
                                     BaselineFrame* frame) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  for (std::size_t i = 0; i < frame->mono.detections.size(); ++i) {
    const int id = frame->mono.light_ids[i];
    if (id < 0) continue;
    points.push_back(dock_.FindLight(id)->p_D);
    pixels.push_back(frame->mono.detections[i].uv);
  }
  const int needed = frame->mono.tracked ? std::min(3, options_.min_mono_lights)
                                         : options_.min_mono_lights;
  if (static_cast<int>(points.size()) < needed) return;
  PnpOptions pnp;
  pnp.pixel_sigma = mono_->pixel_noise_px;
  const PnpResult result = SolvePnp(points, pixels, mono_->intrinsics, pnp, T_C_D_initial);
  if (!result.ok) {
    frame->reason = "mono: " + result.reason;
    return;
  }
  frame->n_mono_lights = static_cast<int>(points.size());
  frame->T_D_B_mono = result.T_C_D.Inverse() * mono_->T_B_C.Inverse();
}

BaselineFrame PaperBaselinePipeline::Process(int64_t t_ns, const cv::Mat& left,
                                             const cv::Mat& right, const cv::Mat& mono) {
  BaselineFrame frame;
  frame.t_ns = t_ns;
  const bool have_stereo = left_ && right_ && !left.empty() && !right.empty();
  const bool have_mono = mono_ && !mono.empty();
  if (have_stereo) {
    frame.left.detections = detector_.Detect(left);
    frame.right.detections = detector_.Detect(right);
    Identify(*left_, t_ns, &frame.left);
    if (frame.left.status != MatchStatus::kOk) {
      Identify(*right_, t_ns, &frame.right);
    } else {
      frame.right.light_ids.assign(frame.right.detections.size(), -1);
      frame.right.status = MatchStatus::kOk;
    }
    StereoPose(&frame);
  }
  if (have_mono) {
    frame.mono.detections = detector_.Detect(mono);
    const std::optional<Pose3> T_C_D = Identify(*mono_, t_ns, &frame.mono);
    if (frame.mono.status == MatchStatus::kOk) MonoPose(T_C_D, &frame);
  }

  const bool stereo = frame.T_D_B_stereo.has_value();
  const bool mono_ok = frame.T_D_B_mono.has_value();
  if (stereo && mono_ok) {
    frame.stage = VisibilityStage::kBoth;
    frame.stereo_weight = static_cast<double>(frame.n_stereo_lights) /
                          (frame.n_stereo_lights + frame.n_mono_lights);
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
    last_T_D_B_ = frame.T_D_B;
    last_t_ns_ = t_ns;
  }
  return frame;
}

}  // namespace auvdock
