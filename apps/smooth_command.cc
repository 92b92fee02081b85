// auvdock smooth --dataset DIR [--dock FILE] --out OUTDIR [--config FILE] [--quiet]
//
// Offline reconstruction of a whole log (SmoothBatch): the per-frame vision pipeline and the
// causal sliding-window run first (their states are the warm start), then every state in one
// sparse problem, with a progress display of the solver's iterations. Writes the same files as
// `auvdock run` (apps/estimate_writer.h) from the batch result; the covariance is each pose's
// marginal in the full problem, so it uses data before and after the pose.
#include <chrono>
#include <cstdio>
#include <limits>
#include <memory>
#include <set>

#include "apps/commands.h"
#include "apps/dataset_input.h"
#include "apps/estimate_writer.h"
#include "apps/help_text.h"
#include "apps/run_summary.h"
#include "apps/sensor_feed.h"
#include "apps/signal_flag.h"
#include "apps/vision_frame_source.h"
#include "auvdock/estimator/batch_smoother.h"
#include "auvdock/estimator/estimator_config.h"
#include "auvdock/estimator/start_state.h"
#include "auvdock/io/dataset.h"
#include "auvdock/io/input_error.h"

namespace auvdock::cli {
namespace {

struct SmoothOptions {
  std::string dataset;
  std::string dock;  // --dock: replaces the dataset's dock.yaml
  std::string out;
  std::string config;
  std::string start;  // --start: a starting state (estimator/start_state.h)
  bool quiet = false;
  bool euroc_csv = false;  // --euroc-csv: also estimate.csv (estimate_writer.h)
  FrameSourceOptions frames;  // --detector, --sync-tolerance-ms, --detections
};

using Clock = std::chrono::steady_clock;
double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

void Smooth(const SmoothOptions& options) {
  const auto start = Clock::now();
  const RunConfig config = options.config.empty() ? RunConfig{} : LoadRunConfig(options.config);
  std::vector<std::string> skipped_rows;
  const Dataset dataset = LoadDatasetWithDock(options.dataset, options.dock, &skipped_rows);
  if (!dataset.calibration.imu) throw InputError(options.dataset + ": calibration has no IMU");
  PrintSkippedRows("smooth", skipped_rows);
  VisionFrameSource source(dataset, options.frames);
  SlidingWindowEstimator estimator(dataset.calibration, RequireDock(dataset), config.estimator);
  if (!options.start.empty()) estimator.SetStartState(LoadStartState(options.start));
  EstimateWriter writer(options.out, options.euroc_csv);

  const CancellationToken cancel = InstallSignalCancellation();
  RunCounters counters;
  std::vector<VisionFrame> frames;
  std::set<int64_t> symmetry_unresolved_t_ns;  // the window's outputs up to the symmetry
  SensorFeed feed(dataset, &estimator);
  // The pipeline's prediction at a frame: the estimate propagated with the IMU up to the frame
  // (causal: samples at or before the frame time).
  const VisionFrameSource::Predictor predict = [&](int64_t t_ns) {
    feed.FeedImuUpTo(t_ns);
    return estimator.PropagatedPose(t_ns);
  };
  while (std::optional<VisionFrame> frame = source.Next(predict)) {
    cancel.ThrowIfCancelled();
    const auto t0 = Clock::now();
    feed.FeedAllUpTo(frame->last_t_ns());
    const std::optional<EstimatorOutput> out = estimator.AddVisionFrame(*frame);
    if (out && out->symmetry_unresolved) symmetry_unresolved_t_ns.insert(out->t_ns);
    // The warm start's own rejections are not this command's: the batch gates again below.
    estimator.TakeRejections();
    counters.backend_s += Seconds(Clock::now() - t0);
    ++counters.frames;
    frames.push_back(std::move(*frame));
    if (!options.quiet && counters.frames % 20 == 0) {
      std::fprintf(stderr, "\rsmooth: sliding window %d/%zu frames", counters.frames,
                   source.num_frames());
    }
  }
  if (!options.quiet) std::fprintf(stderr, "\n");

  BatchSmootherOptions batch;
  batch.start = estimator.applied_start();
  if (!options.quiet) {
    batch.progress = [](int iteration, double cost) {
      std::fprintf(stderr, "\rsmooth: batch iteration %d, cost %.6g   ", iteration, cost);
    };
  }
  const auto t0 = Clock::now();
  const NavigationSamples sensors{dataset.depth, dataset.dvl, estimator.stats().dvl_variance_factor,
                            estimator.stats().depth_variance_factor, dataset.acoustic,
                            dataset.sbl, estimator.stats().sbl_variance_factor, dataset.heading};
  const BatchResult result =
      SmoothBatch(dataset.calibration, *dataset.dock, frames, dataset.imu, estimator.History(),
                  config.estimator, batch, sensors);
  counters.backend_s += Seconds(Clock::now() - t0);
  if (!options.quiet) std::fprintf(stderr, "\n");

  writer.WriteRejections(result.rejections);
  counters.rejections = static_cast<int>(result.rejections.size());
  GoNoGo go_no_go(config.go_no_go);
  size_t next_output = 0;
  for (const VisionFrame& frame : frames) {
    if (next_output < result.outputs.size() && result.outputs[next_output].t_ns == frame.t_ns) {
      EstimatorOutput out = result.outputs[next_output++];
      // The batch keeps the window's choice among a symmetric dock's rival poses.
      out.symmetry_unresolved = symmetry_unresolved_t_ns.count(out.t_ns) > 0;
      counters.symmetry_unresolved += out.symmetry_unresolved;
      const GoNoGoDecision decision = go_no_go.Decide(out);
      counters.go += decision.go;
      writer.Write(out, decision);
    } else {
      writer.WriteNoEstimate(frame.t_ns, go_no_go.NoEstimate("no state at this frame"));
    }
  }
  counters.total_s = Seconds(Clock::now() - start);
  EstimatorStats stats = estimator.stats();
  stats.frames_with_output = result.stats.frames_with_output;
  stats.used_observations = result.stats.used_observations;
  stats.gated_observations = result.stats.gated_observations;
  stats.covariance_failures = result.stats.covariance_failures;
  stats.depth_used = result.stats.depth_used;
  stats.depth_gated = result.stats.depth_gated;
  stats.depth_skipped = result.stats.depth_skipped;
  stats.dvl_used = result.stats.dvl_used;
  stats.dvl_gated = result.stats.dvl_gated;
  stats.dvl_no_lock = result.stats.dvl_no_lock;
  stats.dvl_skipped = result.stats.dvl_skipped;
  stats.usbl_used = result.stats.usbl_used;
  stats.usbl_gated = result.stats.usbl_gated;
  stats.usbl_skipped = result.stats.usbl_skipped;
  stats.sbl_used = result.stats.sbl_used;
  stats.sbl_gated = result.stats.sbl_gated;
  stats.sbl_skipped = result.stats.sbl_skipped;
  // The batch's own offset at the log's end, with its marginal sigma.
  stats.depth_offset_m = result.outputs.empty() ? std::numeric_limits<double>::quiet_NaN()
                                                : result.outputs.back().depth_offset_m;
  stats.depth_offset_sigma_m = result.outputs.empty() ? std::numeric_limits<double>::quiet_NaN()
                                                      : result.outputs.back().depth_offset_sigma_m;
  nlohmann::json summary = MakeRunSummary(source, stats, skipped_rows, counters);
  summary["batch"] = {{"segments", result.segments},
                      {"iterations", result.iterations},
                      {"initial_cost", result.initial_cost},
                      {"final_cost", result.final_cost},
                      {"converged", result.converged}};
  summary["vision_errors"] = {{"white_px", result.vision_errors.white_px},
                              {"slow_px", result.vision_errors.slow_px},
                              {"coordinates", result.vision_errors.coordinates},
                              {"lag_pairs", result.vision_errors.lag_pairs}};
  writer.WriteSummary(summary);
  std::printf(
      "smooth: %d frames -> %s: %d estimates in %d segment(s), %d GO; batch %d "
      "iterations, cost %.6g -> %.6g\n",
      counters.frames, options.out.c_str(), result.stats.frames_with_output, result.segments,
      counters.go, result.iterations, result.initial_cost, result.final_cost);
  for (const auto& [reason, count] : source.no_vision_reasons()) {
    std::printf("  no vision: %d frames: %s\n", count, reason.c_str());
  }
  PrintSymmetryUnresolved("smooth", counters.symmetry_unresolved);
  PrintSensorDisagreements("smooth", stats);
  PrintGivenIdentities(source);
}

}  // namespace

void AddSmoothCommand(CLI::App& root) {
  auto options = std::make_shared<SmoothOptions>();
  CLI::App* sub = root.add_subcommand(
      "smooth", "Batch smoothing of a whole log: trajectory, covariance, go/no-go decisions");
  sub->footer(SmoothHelp());
  sub->add_option("--dataset", options->dataset, "Dataset folder")->required();
  AddDockOption(sub, &options->dock);
  sub->add_option("--out", options->out, "Output folder (must not exist or be empty)")->required();
  sub->add_option("--config", options->config, "Estimator and go/no-go options (YAML)");
  sub->add_option("--start", options->start,
                  "A starting state (YAML: t_ns, p_D, rpy_deg, v_D and their sigmas; an INS's "
                  "output, a surveyed launch): the window starts from it");
  AddFrameSourceOptions(sub, &options->frames,
                        "Replay these light detections (detections.csv: `simulate` with "
                        "render_images false, `frontend`, or a detector of your own) instead of "
                        "the images");
  sub->add_flag("--euroc-csv", options->euroc_csv,
                "Also write estimate.csv: the state in EuRoC's ground-truth columns (timestamp, "
                "p, q w x y z, v, gyro bias, accelerometer bias), the format of evo_traj euroc");
  sub->add_flag("--quiet", options->quiet, "No progress display");
  sub->callback([options] { Smooth(*options); });
}

}  // namespace auvdock::cli
