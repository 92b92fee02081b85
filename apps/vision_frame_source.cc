#include "apps/vision_frame_source.h"

#include "apps/camera_image.h"
#include "apps/cli_validators.h"
#include "apps/dataset_input.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "apps/data_files.h"
#include "apps/reason_class.h"
#include "auvdock/estimator/state_times.h"
#include "auvdock/estimator/vision_frame_builder.h"
#include "auvdock/io/input_error.h"

namespace auvdock::cli {
namespace {

PaperBaselineOptions PipelineOptions(LightDetectorKind detector, const std::string& model) {
  PaperBaselineOptions options;
  options.detector_kind = detector;
  options.learned_detector.model_path = model.empty() ? DefaultLightNetModel() : model;
  return options;
}

using Clock = std::chrono::steady_clock;
double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// Images of the stereo pair further apart than this are not one exposure.
constexpr int64_t kStereoPairToleranceNs = 1000000;

// Half the shortest median frame interval of the cameras (0 with fewer than two images).
// times: each camera's image times, sorted.
int64_t DefaultSyncTolerance(const std::array<std::vector<int64_t>, 3>& times) {
  int64_t shortest = INT64_MAX;
  for (const std::vector<int64_t>& t : times) {
    std::vector<int64_t> intervals;
    for (size_t k = 1; k < t.size(); ++k) {
      if (t[k] > t[k - 1]) intervals.push_back(t[k] - t[k - 1]);
    }
    if (intervals.empty()) continue;
    std::nth_element(intervals.begin(), intervals.begin() + intervals.size() / 2, intervals.end());
    shortest = std::min(shortest, intervals[intervals.size() / 2]);
  }
  return shortest == INT64_MAX ? 0 : shortest / 2 - 1;
}

// Frames (see the header): the earliest unused image and each other camera's next image within
// the tolerance after it. Per frame, the index of each camera's image, or -1.
std::vector<std::array<int, 3>> GroupFrames(const std::array<std::vector<int64_t>, 3>& times,
                                            int64_t sync_tolerance_ns) {
  std::vector<std::array<int, 3>> frames;
  std::array<size_t, 3> next{};
  for (;;) {
    int64_t t0 = INT64_MAX;
    for (int c = 0; c < 3; ++c) {
      if (next[c] < times[c].size()) t0 = std::min(t0, times[c][next[c]]);
    }
    if (t0 == INT64_MAX) break;
    std::array<int, 3> frame = {-1, -1, -1};
    for (int c = 0; c < 3; ++c) {
      const std::vector<int64_t>& t = times[c];
      if (next[c] < t.size() && t[next[c]] - t0 <= sync_tolerance_ns) {
        frame[c] = static_cast<int>(next[c]++);
        // A repeated time stamp of one camera: its first image is used.
        while (next[c] < t.size() && t[next[c]] == t[static_cast<size_t>(frame[c])]) ++next[c];
      }
    }
    frames.push_back(frame);
  }
  return frames;
}

bool FileExists(const std::string& path) { return std::filesystem::is_regular_file(path); }

}  // namespace

LightDetectorKind ParseDetectorKind(const std::string& name) {
  if (name == "blob") return LightDetectorKind::kBlob;
  if (name == "learned") return LightDetectorKind::kLearned;
  throw InputError("--detector: expected blob or learned (got '" + name + "')");
}

std::string DefaultLightNetModel() { return DataPath("models/light_net.onnx"); }

void AddDetectorModelOption(CLI::App* sub, std::string* model) {
  sub->add_option("--detector-model", *model,
                  "The learned detector's ONNX file (default: the shipped " +
                      DefaultLightNetModel() + ")")
      ->check(CLI::ExistingFile);
}

int64_t SyncToleranceNs(double milliseconds) {
  if (!std::isfinite(milliseconds) || milliseconds > 1e6) {
    throw InputError("--sync-tolerance-ms: expected a finite number of milliseconds");
  }
  return milliseconds < 0.0 ? -1 : std::llround(milliseconds * 1e6);
}

void AddFrameSourceOptions(CLI::App* sub, FrameSourceOptions* options,
                           const std::string& detections_help) {
  sub->add_option("--detector", options->detector,
                  "blob (default: scale-space blobs, core centroid, shape and colour checks) or "
                  "learned (the network learned from randomised renders proposes the lights)")
      ->check(CLI::IsMember({"blob", "learned"}));
  AddDetectorModelOption(sub, &options->detector_model);
  sub->add_option("--sync-tolerance-ms", options->sync_tolerance_ms,
                  "Images of different cameras this close in time share one state (default: half "
                  "the shortest frame interval; 0: equal time stamps only)")
      ->check(NonNegative("milliseconds"));
  sub->add_option("--detections", options->detections, detections_help);
  sub->add_option("--state-rate-hz", options->state_rate_hz,
                  "Without cameras (IMU with DVL, depth, fixes, heading): a state this many times "
                  "a second over the IMU's span (default 10)")
      ->check(CLI::PositiveNumber);
}

VisionFrameSource::VisionFrameSource(const Dataset& dataset, const FrameSourceOptions& options)
    : VisionFrameSource(dataset, ParseDetectorKind(options.detector),
                        SyncToleranceNs(options.sync_tolerance_ms), options.detections,
                        options.state_rate_hz, options.detector_model) {}

VisionFrameSource::VisionFrameSource(const Dataset& dataset, LightDetectorKind detector,
                                     int64_t sync_tolerance_ns, const std::string& detections_path,
                                     double state_rate_hz, const std::string& detector_model)
    : pipeline_(dataset.calibration, RequireDock(dataset),
                PipelineOptions(detector, detector_model)) {
  cameras_ = {pipeline_.left_camera(), pipeline_.right_camera(), pipeline_.mono_camera()};
  if (dataset.calibration.cameras.empty() && detections_path.empty()) {
    if (dataset.imu.size() < 2) {
      throw InputError(dataset.root + ": no camera and no IMU samples: no state to estimate");
    }
    without_cameras_ = true;
    for (const int64_t t : StateTimesWithoutCameras(dataset.imu.front().t_ns,
                                                    dataset.imu.back().t_ns, state_rate_hz)) {
      FrameImages frame;
      frame.t_ns = t;
      frames_.push_back(frame);
    }
    if (frames_.empty()) {
      throw InputError(dataset.root + ": the IMU's samples span less than one state interval");
    }
    return;
  }
  if (dataset.calibration.acoustic) {
    fixes_ = dataset.acoustic;
    // In arrival order: the pipeline sees a fix only once it has arrived (causal), and ages it
    // from its measurement time.
    std::stable_sort(fixes_.begin(), fixes_.end(), [](const AcousticFix& a, const AcousticFix& b) {
      return a.arrival_t_ns() < b.arrival_t_ns();
    });
    fix_T_B_S_ = dataset.calibration.acoustic->T_B_S;
  }
  replaying_ = !detections_path.empty();
  if (replaying_) ReadReplay(detections_path, dataset);
  // Each camera's images (or, in replay, its images' detections), in time order.
  std::array<std::vector<const CameraFrame*>, 3> by_camera;
  std::array<std::vector<const ImageDetections*>, 3> replay_by_camera;
  std::array<std::vector<int64_t>, 3> times;
  for (int c = 0; c < 3; ++c) {
    if (!cameras_[c]) continue;
    if (replaying_) {
      for (const ImageDetections& image : replay_) {
        if (image.camera == cameras_[c]->name) replay_by_camera[c].push_back(&image);
      }
      for (const ImageDetections* image : replay_by_camera[c]) times[c].push_back(image->t_ns);
      if (times[c].empty()) {
        std::fprintf(stderr, "auvdock: warning: %s: no image of camera %s; it gives no vision\n",
                     detections_path.c_str(), cameras_[c]->name.c_str());
      }
      continue;
    }
    if (!dataset.camera_frames.count(cameras_[c]->name)) continue;
    for (const CameraFrame& f : dataset.camera_frames.at(cameras_[c]->name)) {
      by_camera[c].push_back(&f);
    }
    std::stable_sort(by_camera[c].begin(), by_camera[c].end(),
                     [](const CameraFrame* a, const CameraFrame* b) { return a->t_ns < b->t_ns; });
    for (const CameraFrame* f : by_camera[c]) times[c].push_back(f->t_ns);
  }
  sync_tolerance_ns_ = sync_tolerance_ns >= 0 ? sync_tolerance_ns : DefaultSyncTolerance(times);
  for (const std::array<int, 3>& indices : GroupFrames(times, sync_tolerance_ns_)) {
    FrameImages frame;
    frame.t_ns = INT64_MAX;
    for (int c = 0; c < 3; ++c) {
      if (indices[c] < 0) continue;
      const size_t k = static_cast<size_t>(indices[c]);
      if (!replaying_) {
        frame.images[c] = by_camera[c][k];
      } else {
        frame.detections[c] = replay_by_camera[c][k];
      }
      frame.t_ns = std::min(frame.t_ns, times[c][k]);
    }
    frames_.push_back(frame);
  }
  if (frames_.empty()) {
    if (replaying_) {
      throw InputError(detections_path + ": no image of the calibration's stereo or mono cameras");
    }
    const std::string detections = dataset.root + "/detections.csv";
    throw InputError(dataset.root + ": no camera frames" +
                     (FileExists(detections)
                          ? " (it has detections: replay them with --detections " + detections + ")"
                          : std::string()));
  }
  for (const std::string& w : pipeline_.warnings()) {
    std::fprintf(stderr, "auvdock: warning: %s\n", w.c_str());
  }
  if (!replaying_) {
    prefetcher_ = std::make_unique<ImagePrefetcher>(frames_.size(), [this](size_t index) {
      const auto start = Clock::now();
      DecodedFrame decoded;
      for (int c = 0; c < 3; ++c) {
        const CameraFrame* image = frames_[index].images[c];
        if (!image) continue;
        std::string problem;
        decoded.images[c] = ReadCameraImage(*image, *cameras_[c], &problem);
        if (!problem.empty()) decoded.problems.push_back(image->path + ": " + problem);
      }
      decoded.decode_s = Seconds(Clock::now() - start);
      return decoded;
    });
  }
}

std::optional<VisionFrame> VisionFrameSource::Next(const Predictor& predict) {
  if (next_ == frames_.size()) return std::nullopt;
  const FrameImages& group = frames_[next_++];
  const int64_t t = group.t_ns;
  if (without_cameras_) {
    VisionFrame state;
    state.t_ns = t;
    ++no_vision_reasons_["no camera in the calibration: a state at --state-rate-hz"];
    return state;
  }
  std::array<cv::Mat, 3> images;
  if (prefetcher_) {
    DecodedFrame decoded = prefetcher_->Take();
    images = std::move(decoded.images);
    for (const std::string& problem : decoded.problems) {
      std::fprintf(stderr, "auvdock: warning: %s; image skipped\n", problem.c_str());
      ++unreadable_images_;
    }
    decode_s_ += decoded.decode_s;
  }
  const auto t1 = Clock::now();
  for (; next_fix_ < fixes_.size() && fixes_[next_fix_].arrival_t_ns() <= t; ++next_fix_) {
    const AcousticFix& fix = fixes_[next_fix_];
    pipeline_.SetPositionFix(fix.t_ns, fix.p_D, fix.sigma_m, fix_T_B_S_);
  }
  const std::optional<Pose3> predicted = predict ? predict(t) : std::nullopt;
  const BaselineFrame frame =
      replaying_ ? Replay(group, predicted)
                 : pipeline_.Process(t, images[0], images[1], images[2], predicted);
  VisionFrame vision = MakeVisionFrame(frame, cameras_[0], cameras_[1], cameras_[2]);
  const auto lag = [&](int c) { return group.image_t_ns(c) - t; };
  vision.stereo_dt_ns = lag(0);
  vision.mono_dt_ns = lag(2);
  if (group.has(0) && group.has(1) && !warned_unsynchronised_pair_ &&
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
  frontend_s_ += Seconds(Clock::now() - t1);
  return vision;
}

void VisionFrameSource::ReadReplay(const std::string& path, const Dataset& dataset) {
  replay_ = ReadDetectionsCsv(path);
  const DockModel& dock = *dataset.dock;
  for (const ImageDetections& image : replay_) {
    const auto where = [&] { return path + ": line " + std::to_string(image.line) + ": "; };
    if (!dataset.calibration.FindCamera(image.camera)) {
      throw InputError(where() + "camera '" + image.camera + "' is not in the calibration");
    }
    for (int id : image.light_ids) {
      if (id >= 0 && !dock.FindLight(id)) {
        throw InputError(where() + "camera '" + image.camera + "' at " +
                         std::to_string(image.t_ns) + " ns: light " + std::to_string(id) +
                         " is not a light of the dock");
      }
    }
  }
}

BaselineFrame VisionFrameSource::Replay(const FrameImages& group,
                                        const std::optional<Pose3>& predicted) {
  std::array<std::optional<std::vector<LightDetection>>, 3> detections;
  std::array<std::vector<int>, 3> ids;
  for (int c = 0; c < 3; ++c) {
    if (!group.detections[c]) continue;
    detections[c] = group.detections[c]->detections;
    ids[c] = group.detections[c]->light_ids;
  }
  GivenIdentities given;
  given.left = ids[0];
  given.right = ids[1];
  given.mono = ids[2];
  BaselineFrame frame = pipeline_.ProcessDetections(group.t_ns, detections[0], detections[1],
                                                    detections[2], predicted, given);
  for (const CameraObservation* obs : {&frame.left, &frame.right, &frame.mono}) {
    given_.dropped += obs->given_dropped;
    if (obs->given_used) {
      ++given_.used;
    } else if (!obs->given_reason.empty()) {
      ++given_.refused[ReasonClass(obs->given_reason)];
    }
  }
  return frame;
}

}  // namespace auvdock::cli
