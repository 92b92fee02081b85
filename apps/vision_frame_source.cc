#include "apps/vision_frame_source.h"

#include <chrono>
#include <cstdio>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "apps/reason_class.h"
#include "auvdock/estimator/vision_frame_builder.h"
#include "auvdock/io/input_error.h"

namespace auvdock::cli {
namespace {

PaperBaselineOptions PipelineOptions(LightDetectorKind detector) {
  PaperBaselineOptions options;
  options.detector_kind = detector;
  return options;
}

using Clock = std::chrono::steady_clock;
double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

const DockModel& RequireDock(const Dataset& dataset) {
  if (!dataset.dock) throw InputError(dataset.root + ": no dock.yaml: the dock's lights are needed");
  return *dataset.dock;
}

cv::Mat ReadImage(const CameraFrame& frame, const CameraCalibration& camera, int* n_bad) {
  cv::Mat image = cv::imread(frame.path, cv::IMREAD_COLOR);
  std::string problem;
  if (image.empty()) {
    problem = "cannot decode";
  } else if (image.cols != camera.intrinsics.width() || image.rows != camera.intrinsics.height()) {
    problem = "is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
              ", calibration says " + std::to_string(camera.intrinsics.width()) + "x" +
              std::to_string(camera.intrinsics.height());
  }
  if (!problem.empty()) {
    std::fprintf(stderr, "auvdock: warning: %s: %s; image skipped\n", frame.path.c_str(),
                 problem.c_str());
    ++*n_bad;
    return cv::Mat();
  }
  return image;
}

}  // namespace

LightDetectorKind ParseDetectorKind(const std::string& name) {
  if (name == "contrast") return LightDetectorKind::kContrast;
  if (name == "blob") return LightDetectorKind::kBlob;
  throw InputError("--detector: expected contrast or blob (got '" + name + "')");
}

VisionFrameSource::VisionFrameSource(const Dataset& dataset, LightDetectorKind detector)
    : pipeline_(dataset.calibration, RequireDock(dataset), PipelineOptions(detector)) {
  cameras_ = {pipeline_.left_camera(), pipeline_.right_camera(), pipeline_.mono_camera()};
  for (int c = 0; c < 3; ++c) {
    if (!cameras_[c] || !dataset.camera_frames.count(cameras_[c]->name)) continue;
    for (const CameraFrame& f : dataset.camera_frames.at(cameras_[c]->name)) {
      frames_by_time_[c][f.t_ns] = &f;
      times_.insert(f.t_ns);
    }
  }
  if (times_.empty()) throw InputError(dataset.root + ": no camera frames");
  for (const std::string& w : pipeline_.warnings()) {
    std::fprintf(stderr, "auvdock: warning: %s\n", w.c_str());
  }
  next_ = times_.begin();
}

std::optional<VisionFrame> VisionFrameSource::Next(const Predictor& predict) {
  if (next_ == times_.end()) return std::nullopt;
  const int64_t t = *next_++;
  const auto t0 = Clock::now();
  std::array<cv::Mat, 3> images;
  for (int c = 0; c < 3; ++c) {
    const auto it = frames_by_time_[c].find(t);
    if (it != frames_by_time_[c].end()) {
      images[c] = ReadImage(*it->second, *cameras_[c], &unreadable_images_);
    }
  }
  const auto t1 = Clock::now();
  const BaselineFrame frame = pipeline_.Process(t, images[0], images[1], images[2],
                                                predict ? predict(t) : std::nullopt);
  VisionFrame vision = MakeVisionFrame(frame, cameras_[0], cameras_[1], cameras_[2]);
  if (vision.empty()) {
    ++no_vision_reasons_[ReasonClass(frame.reason.empty() ? "no identified light" : frame.reason)];
  }
  decode_s_ += Seconds(t1 - t0);
  frontend_s_ += Seconds(Clock::now() - t1);
  return vision;
}

}  // namespace auvdock::cli
