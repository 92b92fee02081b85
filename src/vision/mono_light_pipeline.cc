#include "auvdock/vision/mono_light_pipeline.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace auvdock {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

BlobLightDetectorOptions WeakOptions(const MonoLightPipelineOptions& options) {
  if (!(options.weak_min_response > 0.0) ||
      !(options.weak_halo_fraction >= 0.0 && options.weak_halo_fraction <= 1.0) ||
      !(options.weak_min_support >= 0.0 && options.weak_min_support <= 1.0) ||
      !(options.tracking_motion_px > 0.0) || !(options.unexplained_gate_sigmas >= 0.0) ||
      !(options.unexplained_floor_px >= 0.0) ||
      !(options.unexplained_min_support >= 0.0 && options.unexplained_min_support <= 1.0) ||
      !(options.weak_min_view_elevation_deg >= 0.0 && options.weak_min_view_elevation_deg < 90.0)) {
    throw std::invalid_argument("MonoLightPipelineOptions out of range");
  }
  BlobLightDetectorOptions weak = options.detector;
  weak.candidates.min_response = std::min(weak.candidates.min_response, options.weak_min_response);
  return weak;
}

GuidedLightSearchOptions TrackedSearchOptions(const MonoLightPipelineOptions& options) {
  GuidedLightSearchOptions tracked = options.guided;
  tracked.max_gate_px = std::max(tracked.max_gate_px, options.poser.tracking_gate_px);
  return tracked;
}

// Keeps the detections (and their ids) for which keep(i, id) holds, and counts the kept first-pass
// ones anew.
template <typename Keep>
void KeepDetections(MonoLightFrame* frame, Keep keep) {
  std::vector<LightDetection> detections;
  std::vector<int> ids;
  int first_pass = 0;
  for (size_t i = 0; i < frame->detections.size(); ++i) {
    const int id = frame->pose.light_ids[i];
    if (!keep(static_cast<int>(i), id)) continue;
    first_pass += static_cast<int>(i) < frame->first_pass_detections;
    detections.push_back(frame->detections[i]);
    ids.push_back(id);
  }
  frame->detections = std::move(detections);
  frame->pose.light_ids = std::move(ids);
  frame->first_pass_detections = first_pass;
}

}  // namespace

MonoLightPipeline::MonoLightPipeline(const CameraCalibration& camera, const DockModel& dock,
                                     const MonoLightPipelineOptions& options)
    : camera_(camera),
      dock_(dock),
      options_(options),
      detector_(options.detector),
      learned_detector_(options.learned_first_pass
                            ? std::make_shared<const LearnedLightDetector>(options.learned)
                            : nullptr),
      weak_detector_(WeakOptions(options)),
      pose_search_(options.detector, options.guided),
      tracked_search_(options.detector, TrackedSearchOptions(options)),
      colour_learner_(options.detector.checks.min_halo_excess),
      poser_(camera, dock, options.poser) {}

MonoLightFrame MonoLightPipeline::Process(const cv::Mat& image) {
  MonoLightFrame frame;
  const double halo = options_.learn_colour ? colour_learner_.threshold()
                                            : options_.detector.checks.min_halo_excess;
  const auto t0 = Clock::now();
  // 1. The whole image.
  frame.detections = learned_detector_ ? learned_detector_->Detect(image)
                                       : detector_.Detect(image, &frame.rejected, halo);
  frame.first_pass_detections = static_cast<int>(frame.detections.size());
  // 2. Where the tracked pose puts the lights that 1 did not find.
  const std::optional<Pose3> tracked = poser_.TrackedPose();
  if (options_.guided_search && tracked &&
      frame.first_pass_detections < options_.poser.min_lights) {
    const double s2 = options_.tracking_motion_px * options_.tracking_motion_px;
    std::vector<PredictedLight> predictions =
        PredictLights(dock_, camera_.intrinsics, *tracked, Eigen::Matrix<double, 6, 6>::Zero(), {});
    for (PredictedLight& p : predictions) p.covariance = s2 * Eigen::Matrix2d::Identity();
    for (const GuidedDetection& g :
         tracked_search_.Search(image, predictions, frame.detections, halo)) {
      frame.detections.push_back(g.detection);
    }
  }
  const auto t1 = Clock::now();
  // 3. Identification and pose; step 2's guesses serve tracking only: those it did not identify
  // go, and when it did not track, the first pass's detections are identified from scratch.
  const bool guessed = static_cast<int>(frame.detections.size()) > frame.first_pass_detections;
  if (guessed) {
    frame.pose = poser_.ProcessTrackedOnly(frame.detections);
    if (!frame.pose.T_C_D) {
      frame.detections.resize(frame.first_pass_detections);
      frame.pose = poser_.Retry(frame.detections);
    }
  } else {
    frame.pose = poser_.Process(frame.detections);
  }
  const auto t2 = Clock::now();
  if (guessed && frame.pose.tracked &&
      static_cast<int>(frame.detections.size()) > frame.first_pass_detections) {
    const int first_pass = frame.first_pass_detections;
    KeepDetections(&frame, [&](int i, int id) { return i < first_pass || id >= 0; });
    frame.guided_detections =
        static_cast<int>(frame.detections.size()) - frame.first_pass_detections;
  }
  // 4. No pose: once more with laxer thresholds, keeping what the dock model verifies.
  if (!frame.pose.T_C_D && options_.weak_pass &&
      (frame.first_pass_detections < options_.poser.min_lights ||
       options_.weak_pass_after_failed_identification)) {
    std::vector<LightDetection> weak =
        weak_detector_.Detect(image, nullptr, options_.weak_halo_fraction * halo);
    // The strongest few only: hypothesise-and-verify over many weak blobs costs more than the
    // rest of the frame (and clutter can fit a layout).
    const size_t most = dock_.lights.size() + 4;
    if (weak.size() > most) weak.resize(most);
    if (weak.size() > static_cast<size_t>(frame.first_pass_detections)) {
      const auto t3 = Clock::now();
      // A pose from weak blobs must explain most of the dock it puts in view (clutter can fit a
      // few lights of a layout, rarely most of them); one that does not is not tracked from.
      RansacMatcherOptions weak_view = options_.poser.ransac;
      weak_view.min_view_elevation_deg =
          std::max(weak_view.min_view_elevation_deg, options_.weak_min_view_elevation_deg);
      const auto explains_most = [&](const MonoPoseResult& r) {
        return ExplainsMostOfItsView(dock_, camera_.intrinsics, *r.T_C_D, r.num_lights,
                                     options_.weak_min_support, weak_view);
      };
      MonoPoseResult retry = poser_.Retry(weak, explains_most);
      frame.identify_s += Seconds(t3, Clock::now());
      if (retry.T_C_D) {
        std::vector<LightDetection> kept;
        std::vector<int> ids;
        for (size_t i = 0; i < weak.size(); ++i) {
          if (retry.light_ids[i] < 0) continue;
          kept.push_back(weak[i]);
          ids.push_back(retry.light_ids[i]);
        }
        const size_t identified = kept.size();
        for (int i = 0; i < frame.first_pass_detections; ++i) {
          const LightDetection& d = frame.detections[i];
          const bool same =
              std::any_of(kept.begin(), kept.begin() + identified, [&](const LightDetection& k) {
                return (k.uv - d.uv).norm() <
                       std::max({options_.detector.min_separation_px, k.radius_px, d.radius_px});
              });
          if (same) continue;
          kept.push_back(d);
          ids.push_back(-1);
        }
        frame.detections = std::move(kept);
        retry.light_ids = std::move(ids);
        frame.pose = std::move(retry);
        frame.from_weak_pass = true;
        frame.first_pass_detections = 0;
      }
    }
  }
  // 5. Where the pose puts the lights still missing.
  if (options_.guided_search && frame.pose.T_C_D) {
    frame.guided_detections += SearchMissedLights(
        pose_search_, image, dock_, camera_.intrinsics, *frame.pose.T_C_D,
        frame.pose.covariance_local, 0.0, halo, &frame.detections, &frame.pose.light_ids);
  }
  // 6. What the pose does not explain, far from every light it puts in the image, is not a light
  // of the dock.
  if (frame.pose.T_C_D && !options_.keep_unexplained) {
    PoseVerdictOptions verdict_options;
    verdict_options.gate_sigmas = options_.unexplained_gate_sigmas;
    verdict_options.floor_px = options_.unexplained_floor_px;
    verdict_options.min_support = options_.unexplained_min_support;
    const PoseVerdict verdict(dock_, camera_.intrinsics, *frame.pose.T_C_D,
                              frame.pose.covariance_local, frame.pose.rms_px,
                              frame.pose.num_lights, verdict_options);
    const std::vector<LightDetection> all = frame.detections;
    const std::vector<bool> none = NoLightOfTheDock(all, frame.pose.light_ids, verdict);
    KeepDetections(&frame, [&](int i, int) {
      if (!none[i]) return true;
      frame.unexplained.push_back(all[i]);
      return false;
    });
  }
  frame.detect_s = Seconds(t0, t1) + Seconds(t2, Clock::now()) - frame.identify_s;
  frame.identify_s += Seconds(t1, t2);
  if (frame.pose.T_C_D && options_.learn_colour && !frame.from_weak_pass) {
    colour_learner_.Observe(
        std::vector<LightDetection>(frame.detections.begin(),
                                    frame.detections.begin() + frame.first_pass_detections),
        std::vector<int>(frame.pose.light_ids.begin(),
                         frame.pose.light_ids.begin() + frame.first_pass_detections));
  }
  return frame;
}

}  // namespace auvdock
