// auvdock frontend --dataset DIR [--dock FILE] --out OUTDIR [--dehaze] [--no-tracking]
//                  [--matcher ransac|omnidirectional] [--detector blob|learned]
//
// Runs the paper's per-frame pipeline (PaperBaselinePipeline) over every camera frame (the next
// frames' images decoded ahead on a thread of their own, image_prefetcher.h) and writes, flushed
// frame by frame (a stopped run keeps every frame written before the stop):
//   OUTDIR/detections.csv       timestamp_ns,camera,light_id,u,v,radius,score,cov_uu,cov_uv,
//                               cov_vv (io/detections_csv.h; light_id -1: not identified; an
//                               image without a detection: one row with light_id -1 and the
//                               rest empty), which `run` / `smooth --detections` replay
//   OUTDIR/per_frame.tum        the fused body pose T_D_B (TUM), frames with a pose only
//   OUTDIR/per_frame_stereo.tum the stereo (SVD) pose alone; per_frame_mono.tum the PnP pose
//   OUTDIR/stages.csv           timestamp_ns,stage,n_<camera>... (identified lights per camera),
//                               reason (why there is no pose: the frame's and each camera's)
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <set>

#include "apps/camera_image.h"
#include "apps/commands.h"
#include "apps/dataset_input.h"
#include "apps/help_text.h"
#include "apps/image_prefetcher.h"
#include "apps/reason_class.h"
#include "apps/signal_flag.h"
#include "apps/vision_frame_source.h"
#include "auvdock/io/csv.h"
#include "auvdock/io/dataset.h"
#include "auvdock/io/detections_csv.h"
#include "auvdock/io/input_error.h"
#include "auvdock/io/staged_directory.h"
#include "auvdock/io/tum_io.h"
#include "auvdock/vision/paper_baseline_pipeline.h"

namespace fs = std::filesystem;

namespace auvdock::cli {

namespace {

struct FrontendOptions {
  std::string dataset;
  std::string dock;  // --dock: replaces the dataset's dock.yaml
  std::string out;
  bool dehaze = false;
  bool no_tracking = false;
  std::string matcher = "ransac";
  std::string detector = "blob";
  std::string detector_model;  // --detector-model; empty: the shipped one
  bool quiet = false;
};

using Clock = std::chrono::steady_clock;
double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

void RunFrontend(const FrontendOptions& options) {
  const Dataset dataset = LoadDatasetWithDock(options.dataset, options.dock);
  RequireDock(dataset);
  PaperBaselineOptions pipeline_options;
  pipeline_options.dehaze = options.dehaze;
  pipeline_options.use_tracking = !options.no_tracking;
  pipeline_options.detector_kind = ParseDetectorKind(options.detector);
  pipeline_options.learned_detector.model_path =
      options.detector_model.empty() ? DefaultLightNetModel() : options.detector_model;
  if (options.matcher == "omnidirectional") {
    pipeline_options.matcher = BaselineMatcher::kOmnidirectional;
  } else if (options.matcher != "ransac") {
    throw InputError("--matcher: expected ransac or omnidirectional (got '" + options.matcher +
                     "')");
  }
  PaperBaselinePipeline pipeline(dataset.calibration, *dataset.dock, pipeline_options);
  for (const std::string& w : pipeline.warnings()) {
    std::fprintf(stderr, "auvdock: warning: %s\n", w.c_str());
  }
  const std::vector<const CameraCalibration*> cameras = {
      pipeline.left_camera(), pipeline.right_camera(), pipeline.mono_camera()};

  // Frame times: the union over the cameras; images of one frame share a timestamp.
  std::set<int64_t> times;
  std::vector<std::map<int64_t, const CameraFrame*>> frames_by_time(3);
  for (int c = 0; c < 3; ++c) {
    if (!cameras[c] || !dataset.camera_frames.count(cameras[c]->name)) continue;
    for (const CameraFrame& f : dataset.camera_frames.at(cameras[c]->name)) {
      frames_by_time[c][f.t_ns] = &f;
      times.insert(f.t_ns);
    }
  }
  if (times.empty()) throw InputError(options.dataset + ": no camera frames");

  RequireAbsentOrEmptyDirectory(options.out);
  fs::create_directories(options.out);
  DetectionsCsvWriter detections(options.out + "/detections.csv");
  std::string stage_header = "#timestamp [ns],stage";
  for (const auto* cam : cameras) {
    if (cam) stage_header += ",n_" + cam->name;
  }
  stage_header += ",reason";
  CsvWriter stages(options.out + "/stages.csv", stage_header);
  std::map<std::string, int> no_pose_reasons;
  TumWriter fused(options.out + "/per_frame.tum");
  TumWriter stereo(options.out + "/per_frame_stereo.tum");
  TumWriter mono(options.out + "/per_frame_mono.tum");

  const CancellationToken cancel = InstallSignalCancellation();
  double decode_s = 0.0, frontend_s = 0.0;
  int n_bad_images = 0, n_frames = 0;
  std::map<VisibilityStage, int> n_by_stage;
  // The next frames' images are decoded on a thread of their own (image_prefetcher.h).
  const std::vector<int64_t> frame_times(times.begin(), times.end());
  ImagePrefetcher prefetcher(frame_times.size(), [&](size_t index) {
    const auto start = Clock::now();
    DecodedFrame decoded;
    for (int c = 0; c < 3; ++c) {
      const auto it = frames_by_time[c].find(frame_times[index]);
      if (it == frames_by_time[c].end()) continue;
      std::string problem;
      decoded.images[c] = ReadCameraImage(*it->second, *cameras[c], &problem);
      if (!problem.empty()) {
        decoded.problems.push_back(it->second->path + ": " + problem + "; frame skipped for " +
                                   cameras[c]->name);
      }
    }
    decoded.decode_s = Seconds(Clock::now() - start);
    return decoded;
  });
  for (const int64_t t : frame_times) {
    cancel.ThrowIfCancelled();
    DecodedFrame decoded = prefetcher.Take();
    for (const std::string& problem : decoded.problems) {
      std::fprintf(stderr, "auvdock: warning: %s\n", problem.c_str());
      ++n_bad_images;
    }
    const std::array<cv::Mat, 3>& images = decoded.images;
    const auto t1 = Clock::now();
    const BaselineFrame frame = pipeline.Process(t, images[0], images[1], images[2]);
    const auto t2 = Clock::now();
    decode_s += decoded.decode_s;
    frontend_s += Seconds(t2 - t1);
    ++n_frames;
    ++n_by_stage[frame.stage];

    const CameraObservation* observations[3] = {&frame.left, &frame.right, &frame.mono};
    std::string stage_row = std::to_string(t) + "," + VisibilityStageName(frame.stage);
    for (int c = 0; c < 3; ++c) {
      if (!cameras[c]) continue;
      const CameraObservation& obs = *observations[c];
      if (!images[c].empty()) detections.Append(t, cameras[c]->name, obs.detections, obs.light_ids);
      stage_row += "," + std::to_string(obs.num_identified());
    }
    // Why there is no pose (empty with one); commas would split the column.
    std::string reason = frame.T_D_B ? std::string() : frame.reason;
    for (int c = 0; c < 3 && !frame.T_D_B; ++c) {
      const CameraObservation& obs = *observations[c];
      if (cameras[c] && !obs.reason.empty()) reason += "; " + cameras[c]->name + ": " + obs.reason;
    }
    std::replace(reason.begin(), reason.end(), ',', ';');
    if (!frame.T_D_B) ++no_pose_reasons[ReasonClass(frame.reason)];
    stages.Line(stage_row + "," + reason);
    if (frame.T_D_B) fused.Append({t, *frame.T_D_B});
    if (frame.T_D_B_stereo) stereo.Append({t, *frame.T_D_B_stereo});
    if (frame.T_D_B_mono) mono.Append({t, *frame.T_D_B_mono});
    if (!options.quiet && n_frames % 50 == 0) {
      std::fprintf(stderr, "\rfrontend: %d/%zu frames", n_frames, times.size());
    }
  }
  if (!options.quiet) std::fprintf(stderr, "\n");
  std::printf("frontend: %d frames -> %s (%d images unreadable)\n", n_frames, options.out.c_str(),
              n_bad_images);
  std::printf("  stages:");
  for (int s = 0; s < 4; ++s) {
    std::printf(" %s %d", VisibilityStageName(static_cast<VisibilityStage>(s)),
                n_by_stage[static_cast<VisibilityStage>(s)]);
  }
  std::printf("\n");
  for (const auto& [reason, count] : no_pose_reasons) {
    std::printf("  no pose: %d x %s\n", count, reason.c_str());
  }
  std::printf("  time per frame: decode %.2f ms, front-end %.2f ms (all cameras)\n",
              1e3 * decode_s / n_frames, 1e3 * frontend_s / n_frames);
}

}  // namespace

void AddFrontendCommand(CLI::App& root) {
  auto options = std::make_shared<FrontendOptions>();
  CLI::App* sub = root.add_subcommand(
      "frontend", "Per-frame vision (the paper's pipeline): detections, stages, per-frame poses");
  sub->footer(FrontendHelp());
  sub->add_option("--dataset", options->dataset, "Dataset folder")->required();
  AddDockOption(sub, &options->dock);
  sub->add_option("--out", options->out, "Output folder (must not exist or be empty)")->required();
  sub->add_flag("--dehaze", options->dehaze, "Dark-channel dehazing before detection");
  sub->add_flag("--no-tracking", options->no_tracking,
                "Identify every frame from scratch (the paper's frame-independent matching)");
  sub->add_option("--matcher", options->matcher, "ransac (default) or omnidirectional")
      ->check(CLI::IsMember({"ransac", "omnidirectional"}));
  sub->add_option("--detector", options->detector,
                  "blob (default: blob_light_detector.h, the dock's colour) or learned (the "
                  "network learned from randomised renders: learned_light_detector.h)")
      ->check(CLI::IsMember({"blob", "learned"}));
  AddDetectorModelOption(sub, &options->detector_model);
  sub->add_flag("--quiet", options->quiet, "No progress display");
  sub->callback([options] { RunFrontend(*options); });
}

}  // namespace auvdock::cli
