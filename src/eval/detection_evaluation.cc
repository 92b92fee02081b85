#include "auvdock/eval/detection_evaluation.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <tuple>

namespace auvdock {
namespace {

std::string Where(const std::string& file, const Eigen::Vector2d& uv) {
  std::ostringstream s;
  s.precision(5);
  s << file << ' ' << uv.x() << ' ' << uv.y();
  return s.str();
}

}  // namespace

DetectionEvaluation EvaluateDetections(const LightLabels& labels,
                                       const std::map<std::string, FrameDetections>& frames,
                                       const DetectionEvaluationOptions& options) {
  DetectionEvaluation e;
  std::vector<double> errors;
  for (const auto& [file, frame_labels] : labels) {
    const auto it = frames.find(file);
    if (it == frames.end()) {
      ++e.missing_frames;
      continue;
    }
    ++e.frames;
    const FrameDetections& frame = it->second;
    std::vector<std::tuple<double, int, int>> pairs;
    for (size_t i = 0; i < frame_labels.size(); ++i) {
      for (size_t j = 0; j < frame.uv.size(); ++j) {
        const double d = (frame.uv[j] - frame_labels[i].uv).norm();
        if (d <= options.hit_radius_px) pairs.emplace_back(d, static_cast<int>(i), static_cast<int>(j));
      }
    }
    std::sort(pairs.begin(), pairs.end());
    std::vector<int> detection_of_label(frame_labels.size(), -1);
    std::vector<char> used(frame.uv.size(), 0);
    for (const auto& [d, i, j] : pairs) {
      if (detection_of_label[i] >= 0 || used[j]) continue;
      detection_of_label[i] = j;
      used[j] = 1;
    }
    int ok_in_frame = 0;
    for (size_t i = 0; i < frame_labels.size(); ++i) {
      const LightLabel& label = frame_labels[i];
      if (label.status != LabelStatus::kOk) continue;
      if (label.range_m >= 0.0 && label.range_m > options.max_range_m) continue;
      ++ok_in_frame;
      ++e.ok_labels;
      const int j = detection_of_label[i];
      if (j < 0) {
        e.missed.push_back(Where(file, label.uv));
        continue;
      }
      ++e.hits;
      if (label.good) errors.push_back((frame.uv[j] - label.uv).norm());
    }
    for (size_t j = 0; j < frame.uv.size(); ++j) {
      if (used[j]) {
        ++e.detections;
        ++e.true_detections;
        continue;
      }
      bool near_edge = false;
      for (const LightLabel& label : frame_labels) {
        near_edge = near_edge || (label.status == LabelStatus::kEdge &&
                                  (frame.uv[j] - label.uv).norm() <= options.edge_radius_px);
      }
      if (near_edge) continue;
      ++e.detections;
      e.false_detections.push_back(Where(file, frame.uv[j]));
    }
    if (ok_in_frame >= options.min_lights_for_pose) {
      ++e.pose_frames_eligible;
      if (frame.has_pose) ++e.pose_frames;
    }
  }
  e.recall = e.ok_labels > 0 ? static_cast<double>(e.hits) / e.ok_labels : 0.0;
  e.precision = e.detections > 0 ? static_cast<double>(e.true_detections) / e.detections : 1.0;
  e.centroid_samples = static_cast<int>(errors.size());
  if (!errors.empty()) {
    double sum2 = 0.0;
    for (double err : errors) sum2 += err * err;
    e.centroid_rms_px = std::sqrt(sum2 / errors.size());
    std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
    e.centroid_median_px = errors[errors.size() / 2];
  }
  e.pose_rate = e.pose_frames_eligible > 0
                    ? static_cast<double>(e.pose_frames) / e.pose_frames_eligible
                    : 0.0;
  return e;
}

}  // namespace auvdock
