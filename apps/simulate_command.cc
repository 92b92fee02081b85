// auvdock simulate --scenario FILE.yaml --out DIR [--seed N] [--quiet]
//
// Writes a dataset folder; the folder appears only when the run completes (StagedDirectory).
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>

#include "apps/cli_validators.h"
#include "apps/commands.h"
#include "apps/help_text.h"
#include "apps/signal_flag.h"
#include "auvdock/io/input_error.h"
#include "auvdock/io/measurements.h"
#include "auvdock/io/staged_directory.h"
#include "auvdock/sim/docking_simulator.h"
#include "auvdock/sim/scenario.h"

namespace auvdock::cli {

namespace {

struct SimulateOptions {
  std::string scenario;
  std::string out;
  std::optional<int64_t> seed;
  bool detections_only = false;
  double fault_scale = 1.0;
  bool quiet = false;
};

void RunSimulate(const SimulateOptions& options) {
  Scenario scenario = LoadScenario(options.scenario);
  if (options.seed) {
    if (*options.seed < 0) throw InputError("--seed: must not be negative");
    scenario.seed = static_cast<uint64_t>(*options.seed);
  }
  if (options.detections_only) scenario.cameras.render_images = false;
  if (!(options.fault_scale >= 0.0 && options.fault_scale <= 1000.0)) {
    throw InputError("--fault-scale: expected a factor in [0, 1000]");
  }
  ScaleFaultRates(options.fault_scale, &scenario);
  const CancellationToken cancel = InstallSignalCancellation();
  StagedDirectory out(options.out);
  const DockingSimulator simulator(scenario);

  const auto start = std::chrono::steady_clock::now();
  int last_percent = -1;
  const auto progress = [&](double fraction) {
    const int percent = static_cast<int>(fraction * 100.0);
    if (!options.quiet && percent / 10 != last_percent / 10) {
      std::fprintf(stderr, "\rsimulate: %3d%%", percent);
      std::fflush(stderr);
    }
    last_percent = percent;
  };
  const SimulationSummary summary = simulator.Run(out.staging_path(), cancel, progress);
  out.Commit();
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!options.quiet) std::fprintf(stderr, "\n");

  std::printf("simulated '%s' (seed %llu): %.1f s of data in %.1f s wall time -> %s\n",
              scenario.name.c_str(), static_cast<unsigned long long>(scenario.seed),
              scenario.duration_s, wall_s, out.final_path().c_str());
  std::printf("  %d camera frames x %zu cameras, %d IMU, %d depth, %d DVL, %d acoustic, ",
              summary.n_camera_frames, simulator.calibration().cameras.size(), summary.n_imu,
              summary.n_depth, summary.n_dvl, summary.n_acoustic);
  if (simulator.calibration().sbl) std::printf("%d SBL ranges, ", summary.n_sbl_ranges);
  if (simulator.calibration().heading) std::printf("%d heading, ", summary.n_heading);
  std::printf("%d faults\n", summary.n_faults);
  std::printf("  max speed %.2f m/s; stages:", summary.max_speed_mps);
  for (int i = 0; i < 4; ++i) {
    std::printf(" %s %.1f s", VisibilityStageName(static_cast<VisibilityStage>(i)),
                summary.stage_duration_s[i]);
  }
  std::printf("\n");
}

}  // namespace

void AddSimulateCommand(CLI::App& root) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* sub = root.add_subcommand(
      "simulate", "Simulate a docking run and write a dataset folder with ground truth");
  sub->footer(SimulateHelp());
  sub->add_option("--scenario", options->scenario, "Scenario YAML (e.g. data/scenarios/default.yaml)")
      ->required();
  sub->add_option("--out", options->out, "Output dataset folder (must not exist or be empty)")
      ->required();
  sub->add_option("--seed", options->seed, "Random seed (overrides the scenario's)");
  sub->add_flag("--detections-only", options->detections_only,
                "No images: each camera's light detections into detections.csv (the scenario's "
                "cameras.synthetic_detections), for run/smooth --detections");
  sub->add_option("--fault-scale", options->fault_scale,
                  "Multiply the scenario's fault rates (DVL spikes and biases, acoustic outliers, "
                  "synthetic misses, spurious blobs and wrong ids) by this factor")
      ->check(NonNegative("times the scenario's rates"));
  sub->add_flag("--quiet", options->quiet, "No progress display");
  sub->callback([options] { RunSimulate(*options); });
}

}  // namespace auvdock::cli
