// auvdock run --dataset DIR [--dock FILE] --out OUTDIR [--config FILE] [--quiet]
//
// Causal sliding-window estimation over a dataset (SlidingWindowEstimator): every camera frame
// goes through the per-frame vision pipeline, then into the estimator together with the IMU
// samples up to the frame's timestamp, so each output uses only data up to its own time.
// Files (apps/estimate_writer.h): trajectory.tum, covariance.csv, decisions.csv flushed per
// frame, and summary.json at the end - also after an interruption (SIGINT/SIGTERM, exit 130),
// then with "interrupted": true. Bad sensor rows (NaN/Inf, timestamps out of order) are skipped
// and listed in the summary's log.
#include <chrono>
#include <cstdio>
#include <memory>

#include "apps/commands.h"
#include "apps/dataset_input.h"
#include "apps/estimate_writer.h"
#include "apps/help_text.h"
#include "apps/run_summary.h"
#include "apps/sensor_feed.h"
#include "apps/signal_flag.h"
#include "apps/vision_frame_source.h"
#include "auvdock/estimator/estimator_config.h"
#include "auvdock/estimator/start_state.h"
#include "auvdock/io/dataset.h"
#include "auvdock/io/input_error.h"

namespace auvdock::cli {
namespace {

struct RunOptions {
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

void Run(const RunOptions& options) {
  const auto start = Clock::now();
  const RunConfig config = options.config.empty() ? RunConfig{} : LoadRunConfig(options.config);
  std::vector<std::string> skipped_rows;
  const Dataset dataset = LoadDatasetWithDock(options.dataset, options.dock, &skipped_rows);
  if (!dataset.calibration.imu) throw InputError(options.dataset + ": calibration has no IMU");
  VisionFrameSource source(dataset, options.frames);
  SlidingWindowEstimator estimator(dataset.calibration, RequireDock(dataset), config.estimator);
  if (!options.start.empty()) estimator.SetStartState(LoadStartState(options.start));
  GoNoGo go_no_go(config.go_no_go);
  EstimateWriter writer(options.out, options.euroc_csv);
  PrintSkippedRows("run", skipped_rows);

  const CancellationToken cancel = InstallSignalCancellation();
  RunCounters counters;
  SensorFeed feed(dataset, &estimator);
  // The pipeline's prediction at a frame: the estimate propagated with the IMU up to the frame
  // (causal: samples at or before the frame time).
  const VisionFrameSource::Predictor predict = [&](int64_t t_ns) {
    feed.FeedImuUpTo(t_ns);
    return estimator.PropagatedPose(t_ns);
  };
  size_t log_printed = 0;
  try {
    while (const std::optional<VisionFrame> frame = source.Next(predict)) {
      const auto t0 = Clock::now();
      feed.FeedAllUpTo(frame->last_t_ns());
      const std::optional<EstimatorOutput> out = estimator.AddVisionFrame(*frame);
      counters.backend_s += Seconds(Clock::now() - t0);
      ++counters.frames;
      const std::vector<Rejection> rejections = estimator.TakeRejections();
      counters.rejections += static_cast<int>(rejections.size());
      writer.WriteRejections(rejections);
      if (out) {
        const GoNoGoDecision decision = go_no_go.Decide(*out);
        counters.go += decision.go;
        counters.symmetry_unresolved += out->symmetry_unresolved;
        writer.Write(*out, decision);
      } else {
        const std::string why = estimator.initialized()            ? "estimator reset"
                                : estimator.init_refusal().empty() ? "waiting for a per-frame pose"
                                                                   : estimator.init_refusal();
        writer.WriteNoEstimate(
            frame->t_ns,
            go_no_go.NoEstimate(estimator.initialized() ? why : "not initialised (" + why + ")"));
      }
      const std::vector<std::string>& log = estimator.stats().log;
      for (; log_printed < log.size(); ++log_printed) {
        std::fprintf(stderr, "auvdock: run: %s\n", log[log_printed].c_str());
      }
      if (!options.quiet && counters.frames % 20 == 0) {
        std::fprintf(stderr, "\rrun: %d/%zu frames", counters.frames, source.num_frames());
      }
      cancel.ThrowIfCancelled();
    }
  } catch (const Cancelled&) {
    counters.interrupted = true;
  }
  if (!options.quiet) std::fprintf(stderr, "\n");
  counters.total_s = Seconds(Clock::now() - start);
  writer.WriteSummary(MakeRunSummary(source, estimator.stats(), skipped_rows, counters));
  if (counters.interrupted) throw Cancelled();
  const EstimatorStats& stats = estimator.stats();
  std::printf("run: %d frames -> %s: %d estimates, %d GO, %d resets, %zu skipped rows\n",
              counters.frames, options.out.c_str(), stats.frames_with_output, counters.go,
              stats.resets, skipped_rows.size());
  for (const auto& [reason, count] : source.no_vision_reasons()) {
    std::printf("  no vision: %d frames: %s\n", count, reason.c_str());
  }
  PrintSymmetryUnresolved("run", counters.symmetry_unresolved);
  PrintSensorDisagreements("run", estimator.stats());
  PrintGivenIdentities(source);
  std::printf("  per frame: decode %.2f ms, front-end %.2f ms, back-end %.2f ms\n",
              1e3 * source.decode_s() / counters.frames,
              1e3 * source.frontend_s() / counters.frames,
              1e3 * counters.backend_s / counters.frames);
}

}  // namespace

void AddRunCommand(CLI::App& root) {
  auto options = std::make_shared<RunOptions>();
  CLI::App* sub = root.add_subcommand(
      "run", "Causal sliding-window estimation: trajectory, covariance, go/no-go decisions");
  sub->footer(RunHelp());
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
  sub->callback([options] { Run(*options); });
}

}  // namespace auvdock::cli
