// A light detector measured against hand labels (light_labels_csv.h), frame by frame.
//
// Per labelled frame: detections and labels within hit_radius_px are paired greedily, nearest
// pair first (each used once). Then
//   recall     = hits on `ok` labels / `ok` labels (an `ok` label farther than max_range_m, when
//                its range is known, is not required: a detection of it is a hit, as for
//                `border`);
//   precision  = detections paired with any label / detections, where detections not paired
//                but within edge_radius_px of an `edge` label are left out of both counts;
//   centroid   = RMS of |detection - label| over hits on `ok` labels of quality good (pixels);
//   pose rate  = frames with a pose / frames with at least min_lights_for_pose `ok` labels.
// Only the labelled frames count.
#pragma once

#include <limits>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "auvdock/io/light_labels_csv.h"

namespace auvdock {

struct DetectionEvaluationOptions {
  double hit_radius_px = 10.0;
  double edge_radius_px = 15.0;
  int min_lights_for_pose = 4;
  double max_range_m = std::numeric_limits<double>::infinity();
};

struct FrameDetections {
  std::vector<Eigen::Vector2d> uv;
  bool has_pose = false;
};

struct DetectionEvaluation {
  int frames = 0;             // labelled frames that were processed
  int missing_frames = 0;     // labelled frames absent from the detections
  int ok_labels = 0, hits = 0;
  int detections = 0, true_detections = 0;
  int centroid_samples = 0;
  double recall = 0.0, precision = 0.0;
  double centroid_rms_px = 0.0, centroid_median_px = 0.0;
  int pose_frames_eligible = 0, pose_frames = 0;
  double pose_rate = 0.0;
  std::vector<std::string> missed;  // "frame_file u v" of every missed ok label
  std::vector<std::string> false_detections;  // "frame_file u v"
};

DetectionEvaluation EvaluateDetections(const LightLabels& labels,
                                       const std::map<std::string, FrameDetections>& frames,
                                       const DetectionEvaluationOptions& options = {});

}  // namespace auvdock
