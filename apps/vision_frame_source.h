// The camera side of `auvdock run` / `auvdock smooth`: walks a dataset's camera frames in time
// order, decodes the images (an unreadable or wrong-size image is skipped with a warning) and
// runs the per-frame vision pipeline (detect, identify, triangulate) into the estimator's
// VisionFrame. Times decoding and the front-end separately.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <set>

#include "auvdock/estimator/vision_frame.h"
#include "auvdock/io/dataset.h"
#include "auvdock/vision/paper_baseline_pipeline.h"

namespace auvdock::cli {

// "contrast" or "blob" (the --detector option); throws InputError otherwise.
LightDetectorKind ParseDetectorKind(const std::string& name);

class VisionFrameSource {
 public:
  // Throws InputError when the dataset has no dock or no camera frames.
  explicit VisionFrameSource(const Dataset& dataset,
                             LightDetectorKind detector = LightDetectorKind::kContrast);

  // A body pose T_D_B predicted for a frame time (the estimator's IMU propagation), or nothing.
  using Predictor = std::function<std::optional<Pose3>(int64_t t_ns)>;

  // The next frame, or nothing at the end. predict (optional) lets the pipeline track and
  // resolve a symmetric dock when its own last pose is too old.
  std::optional<VisionFrame> Next(const Predictor& predict = {});

  const std::vector<std::string>& warnings() const { return pipeline_.warnings(); }
  // Frames that gave the estimator no vision, counted by the pipeline's reason.
  const std::map<std::string, int>& no_vision_reasons() const { return no_vision_reasons_; }

  size_t num_frames() const { return times_.size(); }
  int64_t first_t_ns() const { return *times_.begin(); }
  int64_t last_t_ns() const { return *times_.rbegin(); }
  double decode_s() const { return decode_s_; }
  double frontend_s() const { return frontend_s_; }
  int unreadable_images() const { return unreadable_images_; }

 private:
  PaperBaselinePipeline pipeline_;
  std::array<const CameraCalibration*, 3> cameras_{};
  std::array<std::map<int64_t, const CameraFrame*>, 3> frames_by_time_;
  std::set<int64_t> times_;
  std::set<int64_t>::const_iterator next_;
  double decode_s_ = 0.0, frontend_s_ = 0.0;
  int unreadable_images_ = 0;
  std::map<std::string, int> no_vision_reasons_;
};

}  // namespace auvdock::cli
