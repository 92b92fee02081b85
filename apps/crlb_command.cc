// auvdock crlb --dataset DIR [--dock FILE] [--detections FILE] --out FILE.csv [--config FILE]
//
// The Cramér–Rao bound of every pose of a simulated (or otherwise ground-truthed) log
// (estimator/cramer_rao_bound.h): the batch problem's information at the true states with the
// configured noise models, marginalised per pose, written in the covariance.csv format
// (io/pose_covariance_csv.h) so that `auvdock evaluate --bound FILE` sets an estimate's errors
// beside it. The vision frames are the ones `smooth` would get: the images through the same
// per-frame pipeline, or the detections of --detections; the pipeline's prediction of each frame
// is the true pose (the bound assumes the identification that the truth allows). The file is
// written as FILE.partial and renamed when complete: an error or an interruption leaves none.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "apps/commands.h"
#include "apps/dataset_input.h"
#include "apps/help_text.h"
#include "apps/signal_flag.h"
#include "apps/vision_frame_source.h"
#include "auvdock/estimator/cramer_rao_bound.h"
#include "auvdock/estimator/estimator_config.h"
#include "auvdock/eval/truth_interpolation.h"
#include "auvdock/io/csv.h"
#include "auvdock/io/dataset.h"
#include "auvdock/io/input_error.h"

namespace fs = std::filesystem;

namespace auvdock::cli {
namespace {

struct CrlbOptions {
  std::string dataset;
  std::string dock;  // --dock: replaces the dataset's dock.yaml
  std::string out;   // the bound, covariance.csv format
  std::string config;
  FrameSourceOptions frames;  // --detector, --sync-tolerance-ms, --detections
  bool quiet = false;
};

// Writes the bound to out (through out.partial, renamed at the end).
void WriteBound(const std::vector<StampedPoseCovariance>& poses, const std::string& out) {
  const std::string partial = out + ".partial";
  try {
    CsvWriter csv(partial, PoseCovarianceCsvHeader());
    for (const StampedPoseCovariance& p : poses) {
      csv.Row(p.t_ns, PoseCovarianceCsvValues(p.covariance));
    }
    csv.Close();
    fs::rename(partial, out);
  } catch (...) {
    std::error_code ec;
    fs::remove(partial, ec);
    throw;
  }
}

void Crlb(const CrlbOptions& options) {
  const RunConfig config = options.config.empty() ? RunConfig{} : LoadRunConfig(options.config);
  std::vector<std::string> skipped_rows;
  const Dataset dataset = LoadDatasetWithDock(options.dataset, options.dock, &skipped_rows);
  if (!dataset.calibration.imu) throw InputError(options.dataset + ": calibration has no IMU");
  if (dataset.groundtruth.empty()) {
    throw InputError(options.dataset + ": no ground truth (groundtruth/data.csv): the bound is "
                     "evaluated at the true states");
  }
  const DockModel& dock = RequireDock(dataset);
  if (fs::is_directory(options.out)) throw InputError(options.out + ": is a folder, not a file");
  VisionFrameSource source(dataset, options.frames);
  const CancellationToken cancel = InstallSignalCancellation();
  const VisionFrameSource::Predictor truth = [&](int64_t t_ns) -> std::optional<Pose3> {
    GroundTruthState s;
    if (InterpolateTruth(dataset.groundtruth, t_ns, 0.1, &s) != TruthLookup::kFound) {
      return std::nullopt;
    }
    return s.T_D_B;
  };
  std::vector<VisionFrame> frames;
  while (std::optional<VisionFrame> frame = source.Next(truth)) {
    cancel.ThrowIfCancelled();
    frames.push_back(std::move(*frame));
    if (!options.quiet && frames.size() % 20 == 0) {
      std::fprintf(stderr, "\rcrlb: %zu/%zu frames", frames.size(), source.num_frames());
    }
  }
  if (!options.quiet) std::fprintf(stderr, "\n");
  const NavigationSamples sensors{dataset.depth, dataset.dvl, 1.0, 1.0, dataset.acoustic,
                                  dataset.sbl, 1.0, dataset.heading};
  const CramerRaoBound bound = ComputeCramerRaoBound(dataset.calibration, dock, frames, dataset.imu,
                                                     dataset.groundtruth, config.estimator, sensors);
  cancel.ThrowIfCancelled();
  if (bound.poses.empty()) {
    throw InputError("crlb: no pose has a bound (" + std::to_string(bound.frames) + " frames, " +
                     std::to_string(bound.frames_without_truth) + " without ground truth, " +
                     std::to_string(bound.covariance_failures) +
                     " with a rank-deficient problem)");
  }
  WriteBound(bound.poses, options.out);
  double position = 0.0, attitude = 0.0;
  for (const StampedPoseCovariance& p : bound.poses) {
    position += p.covariance.topLeftCorner<3, 3>().trace();
    attitude += p.covariance.bottomRightCorner<3, 3>().trace();
  }
  const double n = static_cast<double>(bound.poses.size());
  std::printf(
      "crlb: %d frames -> %s: %zu poses with a bound (RMS %.1f mm, %.2f mrad); %d vision "
      "observations used, %d gated at the truth\n",
      bound.frames, options.out.c_str(), bound.poses.size(), 1e3 * std::sqrt(position / n),
      1e3 * std::sqrt(attitude / n), bound.stats.used_observations,
      bound.stats.gated_observations);
  if (bound.frames_without_truth > 0) {
    std::printf("  no bound: %d frames outside the ground truth or in a gap of it\n",
                bound.frames_without_truth);
  }
  if (bound.covariance_failures > 0) {
    std::printf("  no bound: %d poses whose information is rank deficient\n",
                bound.covariance_failures);
  }
}

}  // namespace

void AddCrlbCommand(CLI::App& root) {
  auto options = std::make_shared<CrlbOptions>();
  CLI::App* sub = root.add_subcommand(
      "crlb", "Cramér–Rao bound of every pose of a log with ground truth (covariance.csv format)");
  sub->footer(CrlbHelp());
  sub->add_option("--dataset", options->dataset, "Dataset folder (with ground truth)")->required();
  AddDockOption(sub, &options->dock);
  sub->add_option("--out", options->out, "The bound, one 6x6 covariance per pose (CSV file)")
      ->required();
  sub->add_option("--config", options->config, "Estimator options (YAML): the noise models");
  AddFrameSourceOptions(sub, &options->frames,
                        "The light detections to bound (detections.csv) instead of the images'");
  sub->add_flag("--quiet", options->quiet, "No progress display");
  sub->callback([options] { Crlb(*options); });
}

}  // namespace auvdock::cli
