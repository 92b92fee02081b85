// auvdock evaluate: accuracy of an estimated trajectory (TUM file) against a dataset's ground
// truth -- absolute error overall and per visibility stage, relative pose error, and with
// --covariance the consistency of the reported covariances (NEES).
// The metrics are defined in include/auvdock/eval/trajectory_evaluation.h.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "apps/cli_validators.h"
#include "apps/commands.h"
#include "apps/help_text.h"
#include "apps/plot_script.h"
#include "auvdock/estimator/go_no_go.h"
#include "auvdock/eval/trajectory_evaluation.h"
#include "auvdock/geometry/so3.h"
#include "auvdock/io/dataset.h"
#include "auvdock/io/decisions_csv.h"
#include "auvdock/io/input_error.h"
#include "auvdock/io/pose_covariance_csv.h"
#include "auvdock/io/tum_io.h"

namespace auvdock::cli {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

struct EvaluateOptions {
  std::string dataset_dir;
  std::string estimate_path;
  std::string covariance_path;  // optional: NEES against the truth
  std::string decisions_path;   // optional: go/no-go audit
  std::string bound_path;       // optional: Cramér–Rao bound (crlb) beside the errors
  double allowed_lateral_error_m = GoNoGoOptions().allowed_lateral_error_m;
  bool json = false;
  std::string align = "none";
  double rpe_delta_s = 1.0;
  double max_truth_gap_s = 0.1;
  std::string plots_dir;  // optional: PNG plots (plot_script.h)
};

nlohmann::ordered_json Vector3Json(const Eigen::Vector3d& v) {
  return nlohmann::ordered_json::array({v.x(), v.y(), v.z()});
}

// NaN (no covariance in a group) is written as null by nlohmann::json.
void AddNeesJson(const ErrorStats& stats, nlohmann::ordered_json* j) {
  (*j)["nees_n"] = stats.nees_n;
  (*j)["nees_mean"] = stats.nees_mean;
  (*j)["nees_above_95"] = stats.nees_above_95;
  (*j)["nees_correlation_poses"] = stats.nees_correlation_poses;
  (*j)["nees_effective_n"] = stats.nees_effective_n;
}

// NaN (no bound in a group) is written as null by nlohmann::json.
void AddBoundJson(const ErrorStats& stats, nlohmann::ordered_json* j) {
  (*j)["bound_n"] = stats.bound_n;
  (*j)["bound_pos_rms_m"] = stats.bound_pos_rms_m;
  (*j)["bound_att_rms_rad"] = stats.bound_att_rms_rad;
  (*j)["pos_rmse_at_bound_m"] = stats.pos_rmse_at_bound_m;
  (*j)["att_rmse_at_bound_rad"] = stats.att_rmse_at_bound_rad;
}

nlohmann::ordered_json ReportJson(const EvaluateOptions& options, const EvaluationReport& report) {
  nlohmann::ordered_json j;
  j["dataset"] = options.dataset_dir;
  j["estimate"] = options.estimate_path;
  j["n_poses"] = report.overall.n;
  j["n_skipped"] = report.n_skipped;
  j["max_truth_gap_s"] = options.max_truth_gap_s;
  j["pos_rmse_m"] = report.overall.pos_rmse_m;
  j["att_rmse_rad"] = report.overall.att_rmse_rad;
  j["pos_max_abs_m"] = Vector3Json(report.overall.pos_max_abs_m);
  j["att_max_abs_rad"] = Vector3Json(report.overall.att_max_abs_rad);
  j["pos_mean_m"] = Vector3Json(report.overall.pos_mean_m);
  if (!options.covariance_path.empty()) {
    j["covariance"] = options.covariance_path;
    AddNeesJson(report.overall, &j);
  }
  if (!options.bound_path.empty()) {
    j["bound"] = options.bound_path;
    AddBoundJson(report.overall, &j);
  }
  // NaN RMSEs (no pair) are written as null by nlohmann::json.
  j["rpe"] = {{"delta_s", report.rpe.delta_s},
              {"n_pairs", report.rpe.n_pairs},
              {"trans_rmse_m", report.rpe.trans_rmse_m},
              {"rot_rmse_rad", report.rpe.rot_rmse_rad}};
  j["alignment"] = options.align;
  nlohmann::ordered_json T = nlohmann::ordered_json::array();
  const Eigen::Matrix4d M = report.alignment.Matrix();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) T.push_back(M(r, c));
  }
  j["alignment_T"] = T;
  if (!options.decisions_path.empty()) {
    const DecisionAudit& a = report.decisions;
    j["decisions"] = {{"file", options.decisions_path},
                      {"allowed_lateral_error_m", options.allowed_lateral_error_m},
                      {"n_go", a.n_go},
                      {"n_no_go", a.n_no_go},
                      {"n_go_unsafe", a.n_go_unsafe},
                      {"n_go_unmatched", a.n_go_unmatched},
                      {"max_lateral_error_at_go_m", a.max_lateral_error_at_go_m},
                      {"max_yaw_error_at_go_rad", a.max_yaw_error_at_go_rad}};
  }
  nlohmann::ordered_json stages = nlohmann::ordered_json::object();
  for (const auto& [stage, stats] : report.by_stage) {
    stages[VisibilityStageName(stage)] = {{"n", stats.n},
                                          {"pos_rmse_m", stats.pos_rmse_m},
                                          {"att_rmse_rad", stats.att_rmse_rad},
                                          {"pos_max_abs_m", Vector3Json(stats.pos_max_abs_m)},
                                          {"att_max_abs_rad", Vector3Json(stats.att_max_abs_rad)},
                                          {"pos_mean_m", Vector3Json(stats.pos_mean_m)}};
    if (stats.nees_n > 0) AddNeesJson(stats, &stages[VisibilityStageName(stage)]);
    if (stats.bound_n > 0) AddBoundJson(stats, &stages[VisibilityStageName(stage)]);
  }
  j["stages"] = stages;
  return j;
}

void PrintTable(const EvaluateOptions& options, const EvaluationReport& report) {
  std::printf("dataset    %s\n", options.dataset_dir.c_str());
  std::printf("estimate   %s\n", options.estimate_path.c_str());
  std::printf("poses      %d evaluated, %d skipped (outside the ground truth or in gaps > %g s)\n",
              report.overall.n, report.n_skipped, options.max_truth_gap_s);
  std::printf("alignment  %s", options.align.c_str());
  if (options.align == "se3") {
    const Eigen::Vector3d rpy = RollPitchYawFromQuaternion(report.alignment.q);
    const Eigen::Vector3d& t = report.alignment.p;
    std::printf(" (T_align: t = [%.4f %.4f %.4f] m, roll/pitch/yaw = [%.3f %.3f %.3f] deg)", t.x(),
                t.y(), t.z(), rpy.x() * kRadToDeg, rpy.y() * kRadToDeg, rpy.z() * kRadToDeg);
  }
  std::printf("\n\n");

  struct Row {
    const char* name;
    const ErrorStats* stats;
  };
  std::vector<Row> rows = {{"overall", &report.overall}};
  for (const auto& [stage, stats] : report.by_stage) {
    rows.push_back({VisibilityStageName(stage), &stats});
  }

  std::printf("%-20s %7s %9s %9s %9s %9s %9s %9s %9s\n", "position error [m]", "n", "rmse",
              "max|x|", "max|y|", "max|z|", "mean x", "mean y", "mean z");
  for (const Row& row : rows) {
    const ErrorStats& s = *row.stats;
    std::printf("  %-18s %7d %9.4f %9.4f %9.4f %9.4f %9.4f %9.4f %9.4f\n", row.name, s.n,
                s.pos_rmse_m, s.pos_max_abs_m.x(), s.pos_max_abs_m.y(), s.pos_max_abs_m.z(),
                s.pos_mean_m.x(), s.pos_mean_m.y(), s.pos_mean_m.z());
  }
  std::printf("\n%-20s %7s %9s %9s %9s %9s\n", "attitude error [deg]", "n", "rmse", "max|roll|",
              "max|pitch|", "max|yaw|");
  for (const Row& row : rows) {
    const ErrorStats& s = *row.stats;
    std::printf("  %-18s %7d %9.3f %9.3f %9.3f %9.3f\n", row.name, s.n, s.att_rmse_rad * kRadToDeg,
                s.att_max_abs_rad.x() * kRadToDeg, s.att_max_abs_rad.y() * kRadToDeg,
                s.att_max_abs_rad.z() * kRadToDeg);
  }

  if (!options.covariance_path.empty()) {
    std::printf("\n%-20s %7s %9s %9s   (honest: mean 6, 5 %% above %.2f)\n", "NEES (6-DoF pose)",
                "n", "mean", "above 95%", kNees95);
    for (const Row& row : rows) {
      const ErrorStats& s = *row.stats;
      if (s.nees_n == 0) continue;
      std::printf("  %-18s %7d %9.2f %8.1f%%\n", row.name, s.nees_n, s.nees_mean,
                  100.0 * s.nees_above_95);
    }
  }

  if (!options.bound_path.empty()) {
    std::printf("\n%-20s %7s %9s %9s %9s %9s   (rmse over the poses with a bound)\n",
                "Cramer-Rao bound", "n", "pos rmse", "bound", "att rmse", "bound");
    std::printf("%-20s %7s %9s %9s %9s %9s\n", "", "", "[m]", "[m]", "[deg]", "[deg]");
    for (const Row& row : rows) {
      const ErrorStats& s = *row.stats;
      if (s.bound_n == 0) continue;
      std::printf("  %-18s %7d %9.4f %9.4f %9.3f %9.3f\n", row.name, s.bound_n,
                  s.pos_rmse_at_bound_m, s.bound_pos_rms_m, s.att_rmse_at_bound_rad * kRadToDeg,
                  s.bound_att_rms_rad * kRadToDeg);
    }
  }

  if (!options.decisions_path.empty()) {
    const DecisionAudit& a = report.decisions;
    std::printf("\ngo/no-go audit (allowed lateral error %.3f m)\n",
                options.allowed_lateral_error_m);
    std::printf("  %d GO, %d NO-GO; at GO: max true lateral error %.4f m, max yaw error %.3f deg\n",
                a.n_go, a.n_no_go, a.max_lateral_error_at_go_m,
                a.max_yaw_error_at_go_rad * kRadToDeg);
    std::printf("  unsafe GO (true lateral error > allowed): %d", a.n_go_unsafe);
    if (a.n_go_unmatched > 0) std::printf("; GO without a pose or truth: %d", a.n_go_unmatched);
    std::printf("\n");
  }

  std::printf("\nrelative pose error over %g s: %d pairs\n", report.rpe.delta_s,
              report.rpe.n_pairs);
  if (report.rpe.n_pairs > 0) {
    std::printf("  translation rmse  %.4f m\n", report.rpe.trans_rmse_m);
    std::printf("  rotation rmse     %.3f deg\n", report.rpe.rot_rmse_rad * kRadToDeg);
  } else {
    std::printf("  (no pose pair %g s apart within 10 %%)\n", report.rpe.delta_s);
  }
}

void RunEvaluate(const EvaluateOptions& options) {
  EvaluationOptions evaluation;
  if (!ParseAlignment(options.align, &evaluation.alignment)) {
    throw InputError("--align: expected none or se3 (got '" + options.align + "')");
  }
  evaluation.rpe_delta_s = options.rpe_delta_s;
  evaluation.max_truth_gap_s = options.max_truth_gap_s;

  const std::string plot_script = options.plots_dir.empty() ? "" : FindPlotScript();
  const Dataset dataset = LoadDataset(options.dataset_dir);
  if (dataset.groundtruth.empty()) {
    throw InputError(options.dataset_dir + ": dataset has no ground truth");
  }
  const Trajectory estimate = ReadTumTrajectory(options.estimate_path);
  if (estimate.empty()) throw InputError(options.estimate_path + ": trajectory has no poses");

  evaluation.allowed_lateral_error_m = options.allowed_lateral_error_m;
  EstimateReports reports;
  if (!options.covariance_path.empty()) {
    reports.covariances = ReadPoseCovarianceCsv(options.covariance_path);
    if (reports.covariances.empty()) {
      throw InputError(options.covariance_path + ": no covariance rows");
    }
  }
  if (!options.bound_path.empty()) {
    reports.bounds = ReadPoseCovarianceCsv(options.bound_path);
    if (reports.bounds.empty()) throw InputError(options.bound_path + ": no bound rows");
  }
  if (!options.decisions_path.empty()) {
    reports.decisions = ReadDecisionsCsv(options.decisions_path);
    if (reports.decisions.empty()) throw InputError(options.decisions_path + ": no decisions");
  }
  const EvaluationReport report = EvaluateTrajectory(dataset.groundtruth, estimate,
                                                     dataset.visibility, evaluation, reports);
  if (options.json) {
    std::cout << ReportJson(options, report).dump(2) << std::endl;
  } else {
    PrintTable(options, report);
    std::fflush(stdout);
  }
  if (!plot_script.empty()) {
    std::vector<std::string> args = {"--dataset", options.dataset_dir, "--estimate",
                                     options.estimate_path, "--out", options.plots_dir};
    const std::string label =
        std::filesystem::absolute(options.estimate_path).parent_path().filename().string();
    if (!label.empty()) args.insert(args.end(), {"--label", label});
    if (!options.covariance_path.empty()) {
      args.insert(args.end(), {"--covariance", options.covariance_path});
    }
    if (!options.decisions_path.empty()) {
      args.insert(args.end(), {"--decisions", options.decisions_path});
    }
    std::fflush(stdout);
    RunPlotScript(plot_script, args);
  }
}

}  // namespace

void AddEvaluateCommand(CLI::App& root) {
  auto options = std::make_shared<EvaluateOptions>();
  CLI::App* sub = root.add_subcommand(
      "evaluate", "Compare an estimated trajectory (TUM file) with a dataset's ground truth");
  sub->footer(EvaluateHelp());
  sub->add_option("--dataset", options->dataset_dir, "Dataset folder with ground truth")
      ->required()
      ->check(CLI::ExistingDirectory);
  sub->add_option("--estimate", options->estimate_path,
                  "Estimated trajectory: TUM file 't tx ty tz qx qy qz qw' (T_D_B, s, m)")
      ->required()
      ->type_name("FILE.tum");
  sub->add_option("--covariance", options->covariance_path,
                  "The estimate's pose covariances (covariance.csv of run/smooth): adds the "
                  "NEES consistency check")
      ->type_name("FILE.csv");
  sub->add_option("--decisions", options->decisions_path,
                  "The go/no-go decisions (decisions.csv of run/smooth): adds the audit of GO "
                  "against the true lateral error")
      ->type_name("FILE.csv");
  sub->add_option("--bound", options->bound_path,
                  "The Cramer-Rao bound of every pose (auvdock crlb): its RMS beside the "
                  "estimate's errors")
      ->type_name("FILE.csv");
  sub->add_option("--allowed-lateral-error", options->allowed_lateral_error_m,
                  "Lateral error a GO must stay within, metres (default 0.10, as go/no-go)")
      ->check(Positive("metres"))
      ->type_name("METRES");
  sub->add_flag("--json", options->json, "Print one JSON object instead of a table");
  sub->add_option("--align", options->align,
                  "Align the estimate to the truth first: none (default) or se3 (rigid)")
      ->check(CLI::IsMember({"none", "se3"}))
      ->type_name("MODE");
  sub->add_option("--rpe-delta", options->rpe_delta_s,
                  "Time step of the relative pose error, seconds (default 1)")
      ->check(Positive("seconds"))
      ->type_name("SECONDS");
  sub->add_option("--max-truth-gap", options->max_truth_gap_s,
                  "Skip estimate poses between ground-truth samples further apart than this, "
                  "seconds (default 0.1)")
      ->check(Positive("seconds"))
      ->type_name("SECONDS");
  sub->add_option("--plots", options->plots_dir,
                  "Write PNG plots into this folder: trajectory (top and side views), errors per "
                  "axis with the +-3 sigma band, visibility stages, NEES, go/no-go (needs "
                  "/usr/bin/python3 with python3-matplotlib)")
      ->type_name("DIR");
  sub->callback([options]() { RunEvaluate(*options); });
}

}  // namespace auvdock::cli
