#include "apps/vision_frame_source.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
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
  if (!dataset.dock)
    throw InputError(dataset.root + ": no dock.yaml: the dock's lights are needed");
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

// Images of the stereo pair further apart than this are not one exposure.
constexpr int64_t kStereoPairToleranceNs = 1000000;

// Half the shortest median frame interval of the cameras (0 with fewer than two images).
int64_t DefaultSyncTolerance(const std::array<std::vector<const CameraFrame*>, 3>& by_camera) {
  int64_t shortest = INT64_MAX;
  for (const auto& frames : by_camera) {
    std::vector<int64_t> intervals;
    for (size_t k = 1; k < frames.size(); ++k) {
      if (frames[k]->t_ns > frames[k - 1]->t_ns)
        intervals.push_back(frames[k]->t_ns - frames[k - 1]->t_ns);
    }
    if (intervals.empty()) continue;
    std::nth_element(intervals.begin(), intervals.begin() + intervals.size() / 2, intervals.end());
    shortest = std::min(shortest, intervals[intervals.size() / 2]);
  }
  return shortest == INT64_MAX ? 0 : shortest / 2 - 1;
}

}  // namespace

LightDetectorKind ParseDetectorKind(const std::string& name) {
  if (name == "contrast") return LightDetectorKind::kContrast;
  if (name == "blob") return LightDetectorKind::kBlob;
  throw InputError("--detector: expected contrast or blob (got '" + name + "')");
}

int64_t SyncToleranceNs(double milliseconds) {
  if (!std::isfinite(milliseconds) || milliseconds > 1e6) {
    throw InputError("--sync-tolerance-ms: expected a finite number of milliseconds");
  }
  return milliseconds < 0.0 ? -1 : std::llround(milliseconds * 1e6);
}

VisionFrameSource::VisionFrameSource(const Dataset& dataset, LightDetectorKind detector,
                                     int64_t sync_tolerance_ns)
    : pipeline_(dataset.calibration, RequireDock(dataset), PipelineOptions(detector)) {
  cameras_ = {pipeline_.left_camera(), pipeline_.right_camera(), pipeline_.mono_camera()};
  if (dataset.calibration.acoustic) {
    fixes_ = dataset.acoustic;
    // In arrival order: the pipeline sees a fix only once it has arrived (causal), and ages it
    // from its measurement time.
    std::stable_sort(fixes_.begin(), fixes_.end(), [](const AcousticFix& a, const AcousticFix& b) {
      return a.arrival_t_ns() < b.arrival_t_ns();
    });
    fix_T_B_S_ = dataset.calibration.acoustic->T_B_S;
  }
  std::array<std::vector<const CameraFrame*>, 3> by_camera;
  for (int c = 0; c < 3; ++c) {
    if (!cameras_[c] || !dataset.camera_frames.count(cameras_[c]->name)) continue;
    for (const CameraFrame& f : dataset.camera_frames.at(cameras_[c]->name)) {
      by_camera[c].push_back(&f);
    }
    std::stable_sort(by_camera[c].begin(), by_camera[c].end(),
                     [](const CameraFrame* a, const CameraFrame* b) { return a->t_ns < b->t_ns; });
  }
  sync_tolerance_ns_ = sync_tolerance_ns >= 0 ? sync_tolerance_ns : DefaultSyncTolerance(by_camera);
  // Frames: the earliest unused image and each other camera's next image within the tolerance.
  std::array<size_t, 3> next{};
  for (;;) {
    int64_t t0 = INT64_MAX;
    for (int c = 0; c < 3; ++c) {
      if (next[c] < by_camera[c].size()) t0 = std::min(t0, by_camera[c][next[c]]->t_ns);
    }
    if (t0 == INT64_MAX) break;
    FrameImages frame;
    frame.t_ns = t0;
    for (int c = 0; c < 3; ++c) {
      const std::vector<const CameraFrame*>& images = by_camera[c];
      if (next[c] < images.size() && images[next[c]]->t_ns - t0 <= sync_tolerance_ns_) {
        frame.images[c] = images[next[c]++];
        // A repeated time stamp of one camera: its first image is used.
        while (next[c] < images.size() && images[next[c]]->t_ns == frame.images[c]->t_ns) {
          ++next[c];
        }
      }
    }
    frames_.push_back(frame);
  }
  if (frames_.empty()) throw InputError(dataset.root + ": no camera frames");
  for (const std::string& w : pipeline_.warnings()) {
    std::fprintf(stderr, "auvdock: warning: %s\n", w.c_str());
  }
}

std::optional<VisionFrame> VisionFrameSource::Next(const Predictor& predict) {
  if (next_ == frames_.size()) return std::nullopt;
  const FrameImages& group = frames_[next_++];
  const int64_t t = group.t_ns;
  const auto t0 = Clock::now();
  std::array<cv::Mat, 3> images;
  for (int c = 0; c < 3; ++c) {
    if (group.images[c]) images[c] = ReadImage(*group.images[c], *cameras_[c], &unreadable_images_);
  }
  const auto t1 = Clock::now();
  for (; next_fix_ < fixes_.size() && fixes_[next_fix_].arrival_t_ns() <= t; ++next_fix_) {
    const AcousticFix& fix = fixes_[next_fix_];
    pipeline_.SetPositionFix(fix.t_ns, fix.p_D, fix.sigma_m, fix_T_B_S_);
  }
  const BaselineFrame frame =
      pipeline_.Process(t, images[0], images[1], images[2], predict ? predict(t) : std::nullopt);
  VisionFrame vision = MakeVisionFrame(frame, cameras_[0], cameras_[1], cameras_[2]);
  const auto lag = [&](int c) { return group.images[c] ? group.images[c]->t_ns - t : 0; };
  vision.stereo_dt_ns = lag(0);
  vision.mono_dt_ns = lag(2);
  if (group.images[0] && group.images[1] && !warned_unsynchronised_pair_ &&
      std::llabs(lag(0) - lag(1)) > kStereoPairToleranceNs) {
    std::fprintf(stderr,
                 "auvdock: warning: the stereo pair's images at %lld ns are %.1f ms apart; they "
                 "are triangulated as one exposure (synchronise the pair)\n",
                 static_cast<long long>(t),
                 1e-6 * static_cast<double>(std::llabs(lag(0) - lag(1))));
    warned_unsynchronised_pair_ = true;
  }
  if (vision.empty()) {
    ++no_vision_reasons_[ReasonClass(frame.reason.empty() ? "no identified light" : frame.reason)];
  }
  decode_s_ += Seconds(t1 - t0);
  frontend_s_ += Seconds(Clock::now() - t1);
  return vision;
}

}  // namespace auvdock::cli
