// The camera side of `auvdock run` / `auvdock smooth`: walks a dataset's camera frames in time
// order, decodes the images (an unreadable or wrong-size image is skipped with a warning) and
// runs the per-frame vision pipeline (detect, identify, triangulate) into the estimator's
// VisionFrame. The images are decoded a few frames ahead on a thread of their own
// (image_prefetcher.h) while the current frame is processed: the same frames, warnings and
// results as decoding in line, in less wall time. Times decoding and the front-end separately.
//
// Replay (`--detections FILE`, io/detections_csv.h): the frames are the file's images instead of
// the dataset's, grouped the same way; the pipeline identifies their detections
// (PaperBaselinePipeline::ProcessDetections, with the file's light ids as given identities,
// checked against the dock) and nothing is decoded. A camera of the file that the calibration
// does not have, or a light id that the dock does not have, names the file and line.
//
// Cameras that are not synchronised with each other: the images of one frame are the earliest
// image not yet used (at t0) and, of every other camera, its next image within the sync tolerance
// after t0 (by default half the shortest camera's median frame interval, so each image joins the
// frame nearest to it). The frame's state is at t0; each camera's lag behind t0 goes to the
// VisionFrame (mono_dt_ns, stereo_dt_ns) and the estimator moves its observations to t0 with the
// IMU. The stereo pair is triangulated as one exposure: when its two images are more than 1 ms
// apart, a warning says so. A synchronised rig gives the frames it always did.
//
// Without cameras (a calibration without any, a navigator's log of IMU, DVL, depth, fixes,
// heading): frames without images at state_rate_hz over the IMU's span
// (estimator/state_times.h), each an empty VisionFrame: the estimator's states.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "apps/image_prefetcher.h"
#include "auvdock/estimator/vision_frame.h"
#include "auvdock/io/dataset.h"
#include "auvdock/io/detections_csv.h"
#include "auvdock/vision/paper_baseline_pipeline.h"

namespace auvdock::cli {

// "blob" or "learned" (the --detector option); throws InputError otherwise.
LightDetectorKind ParseDetectorKind(const std::string& name);
// The shipped model of the learned detector (data/models/light_net.onnx as the binary finds it).
std::string DefaultLightNetModel();
// Registers --detector-model (the learned detector's ONNX file; empty: DefaultLightNetModel()).
void AddDetectorModelOption(CLI::App* sub, std::string* model);
// The --sync-tolerance-ms option in ns: < 0 (the default) stays < 0; NaN/Inf throw InputError.
int64_t SyncToleranceNs(double milliseconds);

// The command-line options that choose the frames of `run`, `smooth` and `crlb`.
struct FrameSourceOptions {
  std::string detector = "blob";      // --detector
  double sync_tolerance_ms = -1.0;    // --sync-tolerance-ms; < 0: half the shortest interval
  std::string detections;             // --detections: replay this file instead of the images
  double state_rate_hz = 10.0;        // --state-rate-hz: states without cameras
  std::string detector_model;         // --detector-model; empty: DefaultLightNetModel()
};
// Registers --detector, --sync-tolerance-ms and --detections (described by detections_help).
void AddFrameSourceOptions(CLI::App* sub, FrameSourceOptions* options,
                           const std::string& detections_help);

class VisionFrameSource {
 public:
  // Throws InputError when the dataset has no dock or no camera frames (or detections_path,
  // when given, none), or when detections_path is malformed.
  // sync_tolerance_ns < 0: the default above; 0: only images with equal time stamps share a
  // frame. detections_path: replay that detections.csv instead of the images.
  // state_rate_hz: the states' rate when the calibration has no camera. detector_model: the
  // learned detector's ONNX file (empty: DefaultLightNetModel()).
  explicit VisionFrameSource(const Dataset& dataset,
                             LightDetectorKind detector = LightDetectorKind::kBlob,
                             int64_t sync_tolerance_ns = -1,
                             const std::string& detections_path = "", double state_rate_hz = 10.0,
                             const std::string& detector_model = "");
  // The same, from the command line's options.
  VisionFrameSource(const Dataset& dataset, const FrameSourceOptions& options);
  VisionFrameSource(const VisionFrameSource&) = delete;  // its decoder refers to it
  VisionFrameSource& operator=(const VisionFrameSource&) = delete;

  // A body pose T_D_B predicted for a frame time (the estimator's IMU propagation), or nothing.
  using Predictor = std::function<std::optional<Pose3>(int64_t t_ns)>;

  // The next frame, or nothing at the end. predict (optional) lets the pipeline track and
  // resolve a symmetric dock when its own last pose is too old; so do the dataset's acoustic
  // fixes (each from its own time on: causal).
  std::optional<VisionFrame> Next(const Predictor& predict = {});

  const std::vector<std::string>& warnings() const { return pipeline_.warnings(); }
  // Frames that gave the estimator no vision, counted by the pipeline's reason.
  const std::map<std::string, int>& no_vision_reasons() const { return no_vision_reasons_; }
  // Replay only: what became of the identities given with the detections, per camera image.
  struct GivenIdentityCounts {
    int used = 0;     // images whose given identities fit the dock and were used
    int dropped = 0;  // single claims left out of otherwise used identities
    std::map<std::string, int> refused;  // images identified afresh instead, by the reason
  };
  bool replaying() const { return replaying_; }
  const GivenIdentityCounts& given_identities() const { return given_; }

  size_t num_frames() const { return frames_.size(); }
  int64_t first_t_ns() const { return frames_.front().t_ns; }
  int64_t last_t_ns() const { return frames_.back().t_ns; }
  int64_t sync_tolerance_ns() const { return sync_tolerance_ns_; }
  // Seconds of decoding work (on the decoding thread), and of it the part Next() waited for.
  double decode_s() const { return decode_s_; }
  double decode_wait_s() const { return prefetcher_ ? prefetcher_->wait_s() : 0.0; }
  double frontend_s() const { return frontend_s_; }
  int unreadable_images() const { return unreadable_images_; }

 private:
  // One frame's images: stereo left, stereo right, mono (null: none); in replay, their
  // detections instead.
  struct FrameImages {
    int64_t t_ns = 0;
    std::array<const CameraFrame*, 3> images{};
    std::array<const ImageDetections*, 3> detections{};
    int64_t image_t_ns(int c) const {
      return images[c] ? images[c]->t_ns : detections[c] ? detections[c]->t_ns : t_ns;
    }
    bool has(int c) const { return images[c] || detections[c]; }
  };
  void ReadReplay(const std::string& path, const Dataset& dataset);
  BaselineFrame Replay(const FrameImages& group, const std::optional<Pose3>& predicted);

  PaperBaselinePipeline pipeline_;
  std::array<const CameraCalibration*, 3> cameras_{};
  int64_t sync_tolerance_ns_ = 0;
  std::vector<FrameImages> frames_;
  bool replaying_ = false;               // detections.csv instead of the images
  bool without_cameras_ = false;         // no camera in the calibration: states at a rate
  std::vector<ImageDetections> replay_;  // replay: the file's images
  GivenIdentityCounts given_;
  size_t next_ = 0;
  double decode_s_ = 0.0, frontend_s_ = 0.0;
  int unreadable_images_ = 0;
  bool warned_unsynchronised_pair_ = false;
  std::map<std::string, int> no_vision_reasons_;
  // The acoustic fixes, in time order: each is handed to the pipeline (a symmetric dock's poses
  // told apart) by the first frame at or after its time.
  std::vector<AcousticFix> fixes_;
  size_t next_fix_ = 0;
  Pose3 fix_T_B_S_;
  // Decodes the coming frames' images ahead on its own thread (image_prefetcher.h); none in
  // replay. Last: destroyed (its thread stopped) before what it reads.
  std::unique_ptr<ImagePrefetcher> prefetcher_;
};

}  // namespace auvdock::cli
