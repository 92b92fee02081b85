// auvdock demo [--out DIR] [--scenario FILE] [--seed N] [--quiet]
//
// The README's first command ends here: simulate a scenario (by default the shipped default
// one), run the paper's per-frame baseline (`frontend`), the causal window (`run`) and the batch
// smoother (`smooth`) on it, compute the Cramér–Rao bound of every pose (`crlb`), evaluate all
// three against the ground truth and the bound, and print one table side by side: per
// visibility stage and overall, the position and attitude RMSE and the largest error per axis;
// the bound's RMS over each estimator's poses and the RMSE's ratio to it; the mean NEES of the
// reported covariance; the go/no-go audit; and the wall time as a multiple of real time. Each
// step is the subcommand itself, run again as a child process (child_process.h), so the demo
// shows exactly what a user's own calls give.
// Writes into DIR (must not exist or be empty): dataset/, frontend/, run/, smooth/ (each
// subcommand's files), crlb.csv (the bound), plots/ (evaluate --plots of run), evaluation.json
// (the three evaluations and the wall times) and demo.log (every step's standard error).
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/child_process.h"
#include "apps/commands.h"
#include "apps/data_files.h"
#include "apps/help_text.h"
#include "auvdock/io/cancellation.h"
#include "auvdock/io/input_error.h"

namespace fs = std::filesystem;

namespace auvdock::cli {
namespace {

struct DemoOptions {
  std::string out = "out/demo";
  std::string scenario;  // default: the shipped default scenario
  int seed = -1;         // < 0: the scenario's own
  bool quiet = false;
};

class DemoSteps {
 public:
  DemoSteps(const std::string& log, bool quiet, int total)
      : log_(log), quiet_(quiet), total_(total) {}

  // Runs `auvdock ARGS...` as step `what`; InputError (the step's own last line) when it fails
  // and may not, Cancelled when it was interrupted. `why` receives a failure's reason.
  ChildResult Run(const std::string& what, const std::vector<std::string>& args,
                  std::string* why = nullptr) {
    ++step_;
    if (!quiet_) {
      std::printf("[%d/%d] %s ... ", step_, total_, what.c_str());
      std::fflush(stdout);
    }
    const ChildResult result = RunSelf(args, log_);
    // 130: the step stopped on SIGINT (its own exit status, or the signal's); 143: SIGTERM.
    if (result.exit_status == 128 + SIGINT || result.exit_status == 128 + SIGTERM) {
      throw Cancelled();
    }
    if (result.exit_status != 0) {
      const std::string reason = LastLineOf(log_);
      if (!quiet_) std::printf("failed: %s\n", reason.c_str());
      if (why) {
        *why = reason;
        return result;
      }
      throw InputError("demo: " + what + " failed (exit " + std::to_string(result.exit_status) +
                       ")" + (reason.empty() ? "" : ": " + reason) + " (log: " + log_ + ")");
    }
    if (!quiet_) std::printf("%.1f s\n", result.wall_s);
    return result;
  }

 private:
  std::string log_;
  bool quiet_;
  int total_;
  int step_ = 0;
};

nlohmann::json ParseEvaluation(const ChildResult& result, const std::string& what) {
  try {
    return nlohmann::json::parse(result.out);
  } catch (const nlohmann::json::exception&) {
    throw InputError("demo: evaluate " + what + " printed no JSON");
  }
}

// The node at `path` in an evaluation, or nullptr when absent.
const nlohmann::json* Find(const nlohmann::json& j, const std::vector<std::string>& path) {
  const nlohmann::json* node = &j;
  for (const std::string& key : path) {
    if (!node->is_object() || !node->contains(key)) return nullptr;
    node = &node->at(key);
  }
  return node;
}

// A number from an evaluation, or NaN when absent.
double Get(const nlohmann::json& j, const std::vector<std::string>& path) {
  const nlohmann::json* node = Find(j, path);
  return node != nullptr && node->is_number() ? node->get<double>() : std::nan("");
}

std::string Cell(double value, const char* format) {
  if (!std::isfinite(value)) return "-";
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

void PrintRow(const std::string& label, const std::vector<std::string>& cells) {
  std::printf("  %-38s", label.c_str());
  for (const std::string& c : cells) std::printf(" %16s", c.c_str());
  std::printf("\n");
}

void RunDemo(const DemoOptions& options) {
  const std::string scenario =
      options.scenario.empty() ? DataPath("scenarios/default.yaml") : options.scenario;
  if (!fs::exists(scenario)) throw InputError(scenario + ": no such scenario file");
  std::error_code ec;
  if (fs::exists(options.out, ec) && !fs::is_empty(options.out, ec)) {
    throw InputError(options.out + ": output folder exists and is not empty");
  }
  fs::create_directories(options.out);
  const fs::path out(options.out);
  const std::string log = (out / "demo.log").string();
  const std::string dataset = (out / "dataset").string();
  DemoSteps steps(log, options.quiet, 9);

  std::vector<std::string> simulate = {"simulate", "--scenario", scenario,
                                       "--out",    dataset,      "--quiet"};
  if (options.seed >= 0) {
    simulate.push_back("--seed");
    simulate.push_back(std::to_string(options.seed));
  }
  steps.Run("simulate the scenario", simulate);
  struct Estimator {
    std::string name, title, folder, trajectory;
    bool has_covariance;
    double wall_s = 0.0;
    nlohmann::json evaluation;  // null when there is none
    std::string why_none;       // then: why (evaluate's own message)
  };
  std::vector<Estimator> estimators = {
      {"frontend",
       "per-frame baseline (frontend)",
       "frontend",
       "per_frame.tum",
       false,
       0.0,
       {},
       ""},
      {"run", "causal window (run)", "run", "trajectory.tum", true, 0.0, {}, ""},
      {"smooth", "batch smoother (smooth)", "smooth", "trajectory.tum", true, 0.0, {}, ""}};
  for (Estimator& e : estimators) {
    const std::string folder = (out / e.folder).string();
    e.wall_s =
        steps.Run(e.title, {e.name, "--dataset", dataset, "--out", folder, "--quiet"}).wall_s;
  }
  // The bound is optional: without it the table leaves its rows empty.
  const std::string bound = (out / "crlb.csv").string();
  std::string bound_failed;
  steps.Run("Cramer-Rao bound (crlb)",
            {"crlb", "--dataset", dataset, "--out", bound, "--quiet"}, &bound_failed);
  for (Estimator& e : estimators) {
    const std::string folder = (out / e.folder).string();
    std::vector<std::string> args = {
        "evaluate", "--dataset", dataset, "--estimate", folder + "/" + e.trajectory, "--json"};
    if (bound_failed.empty()) args.insert(args.end(), {"--bound", bound});
    if (e.has_covariance) {
      args.insert(args.end(), {"--covariance", folder + "/covariance.csv", "--decisions",
                               folder + "/decisions.csv"});
    }
    const ChildResult result = steps.Run("evaluate " + e.name, args, &e.why_none);
    if (result.exit_status == 0) e.evaluation = ParseEvaluation(result, e.name);
  }
  const std::string run_folder = (out / "run").string();
  std::string plots_failed;
  steps.Run("plots of run",
            {"evaluate", "--dataset", dataset, "--estimate", run_folder + "/trajectory.tum",
             "--covariance", run_folder + "/covariance.csv", "--decisions",
             run_folder + "/decisions.csv", "--plots", (out / "plots").string()},
            &plots_failed);

  // The data's duration and frame count, from run's summary.
  double duration_s = std::nan("");
  int frames = 0;
  {
    std::ifstream in((out / "run" / "summary.json").string());
    nlohmann::json summary = nlohmann::json::parse(in, nullptr, false);
    duration_s = Get(summary, {"data_duration_s"});
    frames = static_cast<int>(Get(summary, {"frames"}));
  }
  nlohmann::ordered_json record;
  record["scenario"] = scenario;
  record["data_duration_s"] = duration_s;
  record["bound"] = bound_failed.empty() ? nlohmann::json(bound) : nlohmann::json(nullptr);
  if (!bound_failed.empty()) record["no_bound"] = bound_failed;
  for (const Estimator& e : estimators) {
    record[e.name] = {{"wall_s", e.wall_s}, {"evaluation", e.evaluation}};
    if (e.evaluation.is_null()) record[e.name]["no_evaluation"] = e.why_none;
  }
  std::ofstream((out / "evaluation.json").string()) << record.dump(2) << "\n";

  std::printf("\nauvdock demo: %s, %.1f s of data, %d frames -> %s\n\n", scenario.c_str(),
              duration_s, frames, options.out.c_str());
  std::vector<std::string> header;
  for (const Estimator& e : estimators) header.push_back(e.name);
  PrintRow("", header);
  auto row = [&](const std::string& label, auto cell) {
    std::vector<std::string> cells;
    for (const Estimator& e : estimators) cells.push_back(cell(e));
    PrintRow(label, cells);
  };
  row("poses / frames", [&](const Estimator& e) {
    return Cell(Get(e.evaluation, {"n_poses"}), "%.0f") + " / " + std::to_string(frames);
  });
  // Per visibility stage, then over all poses: position RMSE, its largest error per axis of D,
  // attitude RMSE (geodesic) and the largest roll / pitch / yaw error.
  const auto triple = [](const nlohmann::json& j, const std::vector<std::string>& path,
                         const char* format) {
    const nlohmann::json* node = Find(j, path);
    if (node == nullptr || !node->is_array() || node->size() != 3) return std::string("-");
    return Cell(1e3 * (*node)[0].get<double>(), format) + "/" +
           Cell(1e3 * (*node)[1].get<double>(), format) + "/" +
           Cell(1e3 * (*node)[2].get<double>(), format);
  };
  for (const auto& [key, name] : std::vector<std::pair<std::string, std::string>>{
           {"stereo_only", "stereo only"}, {"both", "both"}, {"mono_only", "mono only"},
           {"", "all"}}) {
    std::vector<std::string> path;
    if (!key.empty()) path = {"stages", key};
    const auto at = [&](const std::string& field) {
      std::vector<std::string> p = path;
      p.push_back(field);
      return p;
    };
    row(name + ": position RMSE [mm]", [&](const Estimator& e) {
      return Cell(1e3 * Get(e.evaluation, at("pos_rmse_m")), "%.1f");
    });
    row(name + ": max |x|/|y|/|z| [mm]",
        [&](const Estimator& e) { return triple(e.evaluation, at("pos_max_abs_m"), "%.0f"); });
    row(name + ": attitude RMSE [mrad]", [&](const Estimator& e) {
      return Cell(1e3 * Get(e.evaluation, at("att_rmse_rad")), "%.2f");
    });
    row(name + ": max roll/pitch/yaw [mrad]",
        [&](const Estimator& e) { return triple(e.evaluation, at("att_max_abs_rad"), "%.1f"); });
  }
  row("Cramer-Rao bound RMS [mm] / [mrad]", [&](const Estimator& e) {
    return Cell(1e3 * Get(e.evaluation, {"bound_pos_rms_m"}), "%.1f") + " / " +
           Cell(1e3 * Get(e.evaluation, {"bound_att_rms_rad"}), "%.2f");
  });
  row("RMSE / bound, position / attitude", [&](const Estimator& e) {
    return Cell(Get(e.evaluation, {"pos_rmse_at_bound_m"}) / Get(e.evaluation, {"bound_pos_rms_m"}),
                "%.2f") +
           " / " +
           Cell(Get(e.evaluation, {"att_rmse_at_bound_rad"}) /
                    Get(e.evaluation, {"bound_att_rms_rad"}),
                "%.2f");
  });
  row("mean NEES (6 dof: 6 if honest)",
      [&](const Estimator& e) { return Cell(Get(e.evaluation, {"nees_mean"}), "%.2f"); });
  row("GO decisions (unsafe)", [&](const Estimator& e) {
    const double go = Get(e.evaluation, {"decisions", "n_go"});
    return std::isfinite(go)
               ? Cell(go, "%.0f") + " (" +
                     Cell(Get(e.evaluation, {"decisions", "n_go_unsafe"}), "%.0f") + ")"
               : std::string("-");
  });
  row("wall time [s] (x real time)", [&](const Estimator& e) {
    return Cell(e.wall_s, "%.1f") + " (" + Cell(duration_s / e.wall_s, "%.1f") + "x)";
  });
  for (const Estimator& e : estimators) {
    if (e.evaluation.is_null()) {
      std::printf("\n  %s: no evaluation: %s", e.name.c_str(), e.why_none.c_str());
    }
  }
  if (!bound_failed.empty()) std::printf("\n  no Cramer-Rao bound: %s", bound_failed.c_str());
  std::printf(
      "\n  bound: the best any unbiased estimator could do with these measurements under the\n"
      "  configured noise models (crlb); a ratio below 1: the data are better than configured.\n");
  std::printf(
      "\n  frontend: the paper's per-frame pipeline (no IMU, no covariance, no decision); run: "
      "causal,\n  as the vehicle would use it; smooth: the whole log at once. Plots of run: %s\n",
      plots_failed.empty() ? (out / "plots").string().c_str()
                           : ("none (" + plots_failed + ")").c_str());
}

}  // namespace

void AddDemoCommand(CLI::App& root) {
  auto options = std::make_shared<DemoOptions>();
  CLI::App* sub = root.add_subcommand(
      "demo",
      "Simulate, run the per-frame baseline, the window and the smoother, and compare them");
  sub->footer(DemoHelp());
  sub->add_option("--out", options->out,
                  "Output folder (must not exist or be empty; default out/demo)");
  sub->add_option("--scenario", options->scenario, "Scenario YAML (default: the shipped default)");
  sub->add_option("--seed", options->seed, "Random seed (default: the scenario's)");
  sub->add_flag("--quiet", options->quiet, "No progress lines");
  sub->callback([options] { RunDemo(*options); });
}

}  // namespace auvdock::cli
