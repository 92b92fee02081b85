#include "apps/run_summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace auvdock::cli {

nlohmann::json MakeRunSummary(const VisionFrameSource& source, const EstimatorStats& stats,
                              const std::vector<std::string>& skipped_rows,
                              const RunCounters& counters) {
  const double data_duration_s = 1e-9 * static_cast<double>(source.last_t_ns() -
                                                             source.first_t_ns());
  const double without_decode = source.frontend_s() + counters.backend_s;
  nlohmann::json summary;
  summary["interrupted"] = counters.interrupted;
  summary["frames"] = counters.frames;
  summary["frames_in_dataset"] = source.num_frames();
  summary["estimates"] = stats.frames_with_output;
  summary["go_decisions"] = counters.go;
  summary["symmetry_unresolved_estimates"] = counters.symmetry_unresolved;
  summary["rejections"] = counters.rejections;
  summary["unreadable_images"] = source.unreadable_images();
  summary["imu_samples"] = stats.imu_samples;
  summary["skipped"] = {{"dataset_rows", skipped_rows.size()},
                        {"imu_samples", stats.skipped_imu},
                        {"frames", stats.skipped_frames},
                        {"observations", stats.skipped_observations}};
  summary["vision_residuals"] = {{"used", stats.used_observations},
                                 {"gated", stats.gated_observations}};
  summary["depth_samples"] = {{"used", stats.depth_used},
                              {"gated", stats.depth_gated},
                              {"skipped", stats.depth_skipped}};
  summary["dvl_samples"] = {{"used", stats.dvl_used},
                            {"gated", stats.dvl_gated},
                            {"no_bottom_lock", stats.dvl_no_lock},
                            {"rate_test_rejected", stats.dvl_rate_rejected},
                            {"not_admitted", stats.dvl_not_admitted},
                            {"skipped", stats.dvl_skipped}};
  summary["usbl_fixes"] = {{"used", stats.usbl_used},
                           {"gated", stats.usbl_gated},
                           {"rate_test_rejected", stats.usbl_rate_rejected},
                           {"skipped", stats.usbl_skipped}};
  summary["sbl_ranges"] = {{"used", stats.sbl_used},
                           {"gated", stats.sbl_gated},
                           {"rate_test_rejected", stats.sbl_rate_rejected},
                           {"skipped", stats.sbl_skipped}};
  summary["heading_samples"] = {{"used", stats.heading_used},
                                {"gated", stats.heading_gated},
                                {"skipped", stats.heading_skipped}};
  summary["acoustic_starts"] = stats.acoustic_starts;
  if (std::isfinite(stats.depth_offset_m)) {
    // estimate_depth_offset: the depth sensor's offset at the last estimate (sigma null when
    // its covariance was not computed).
    summary["depth_offset"] = {
        {"m", stats.depth_offset_m},
        {"sigma_m", std::isfinite(stats.depth_offset_sigma_m)
                        ? nlohmann::json(stats.depth_offset_sigma_m)
                        : nlohmann::json(nullptr)}};
  }
  summary["no_vision_reasons"] = source.no_vision_reasons();
  if (source.replaying()) {
    const VisionFrameSource::GivenIdentityCounts& given = source.given_identities();
    summary["given_identities"] = {
        {"used", given.used}, {"dropped", given.dropped}, {"refused", given.refused}};
  }
  summary["warnings"] = source.warnings();
  if (const std::string depth = DepthDisagreementWarning(stats); !depth.empty()) {
    summary["warnings"].push_back(depth);
  }
  if (const std::string dvl = DvlDisagreementWarning(stats); !dvl.empty()) {
    summary["warnings"].push_back(dvl);
  }
  if (const std::string usbl = UsblDisagreementWarning(stats); !usbl.empty()) {
    summary["warnings"].push_back(usbl);
  }
  summary["adaptive_variance_factor"] = {{"mono", stats.mono_variance_factor},
                                         {"stereo", stats.stereo_variance_factor},
                                         {"dvl", stats.dvl_variance_factor},
                                         {"depth", stats.depth_variance_factor},
                                         {"sbl", stats.sbl_variance_factor}};
  // The sliding window's slow-error floor at the end (px; window_vision_floor_px, raised to
  // what the residuals show).
  summary["window_vision_floor_px"] = stats.window_vision_floor_px;
  summary["window_vision_correlation_time_s"] = stats.window_vision_correlation_time_s;
  summary["resets"] = stats.resets;
  summary["divergences"] = stats.divergences;  // resets for fixes the gate refused (divergence)
  summary["init_refused"] = stats.init_refused;
  summary["solver_failures"] = stats.solver_failures;
  summary["covariance_failures"] = stats.covariance_failures;
  summary["data_duration_s"] = data_duration_s;
  summary["timing_s"] = {{"decode", source.decode_s()},
                         {"decode_waited", source.decode_wait_s()},
                         {"frontend", source.frontend_s()},
                         {"backend", counters.backend_s},
                         {"total", counters.total_s}};
  summary["realtime_factor"] = {
      {"total", data_duration_s / std::max(1e-9, counters.total_s)},
      {"without_decode", data_duration_s / std::max(1e-9, without_decode)},
      {"backend", data_duration_s / std::max(1e-9, counters.backend_s)}};
  std::vector<std::string> log = skipped_rows;
  log.insert(log.end(), stats.log.begin(), stats.log.end());
  summary["log"] = log;
  return summary;
}

void PrintSkippedRows(const char* command, const std::vector<std::string>& skipped_rows,
                      std::size_t max_lines) {
  for (std::size_t i = 0; i < skipped_rows.size() && i < max_lines; ++i) {
    std::fprintf(stderr, "auvdock: %s: %s\n", command, skipped_rows[i].c_str());
  }
  if (skipped_rows.size() > max_lines) {
    std::fprintf(stderr,
                 "auvdock: %s: ... and %zu more rows skipped (summary.json \"log\" lists them)\n",
                 command, skipped_rows.size() - max_lines);
  }
}

std::string DepthDisagreementWarning(const EstimatorStats& stats) {
  const int samples = stats.depth_used + stats.depth_gated;
  if (std::isfinite(stats.depth_offset_m) || samples < 20 || 4 * stats.depth_gated <= samples) {
    return {};
  }
  return "the depth gate rejected " + std::to_string(stats.depth_gated) + " of " +
         std::to_string(samples) +
         " depth samples: the depth disagrees with the other sensors; if the sensor's zero is "
         "not the dock survey's (tide, air pressure, water density), set estimate_depth_offset: "
         "true";
}

std::string DvlDisagreementWarning(const EstimatorStats& stats) {
  const int refused = stats.dvl_gated + stats.dvl_rate_rejected + stats.dvl_not_admitted;
  const int samples = stats.dvl_used + refused;
  if (samples < 20 || 2 * refused <= samples) return {};
  return "the DVL's rate test, admission and gate refused " + std::to_string(refused) + " of " +
         std::to_string(samples) +
         " DVL samples: its velocity disagrees with the IMU's and the other sensors; check the "
         "DVL's frame (calibration T_B_S) and its time stamps";
}

std::string UsblDisagreementWarning(const EstimatorStats& stats) {
  const int samples = stats.usbl_used + stats.usbl_gated;
  if (samples < 10 || 2 * stats.usbl_gated <= samples) return {};
  return "the gate refused " + std::to_string(stats.usbl_gated) + " of " + std::to_string(samples) +
         " acoustic fixes: they disagree with the lights and the other sensors; check that "
         "the fixes are in the dock frame D (its origin, its axes, the dock's heading)";
}

void PrintSensorDisagreements(const char* command, const EstimatorStats& stats) {
  for (const std::string& warning : {DepthDisagreementWarning(stats), DvlDisagreementWarning(stats),
                                     UsblDisagreementWarning(stats)}) {
    if (!warning.empty()) {
      std::fprintf(stderr, "auvdock: %s: warning: %s\n", command, warning.c_str());
    }
  }
}

void PrintSymmetryUnresolved(const char* command, int count) {
  if (count == 0) return;
  std::printf("  %s: %d estimates are known only up to the dock's symmetry: nothing told its "
              "rival poses apart (give dock.yaml approach_direction_D, or acoustic fixes); they "
              "are NO-GO\n",
              command, count);
}

void PrintGivenIdentities(const VisionFrameSource& source) {
  if (!source.replaying()) return;
  const VisionFrameSource::GivenIdentityCounts& given = source.given_identities();
  int refused = 0;
  for (const auto& [reason, count] : given.refused) refused += count;
  if (given.used == 0 && refused == 0) return;  // the file gave no identities
  std::printf("  given identities: used in %d images (%d claims left out), refused in %d\n",
              given.used, given.dropped, refused);
  for (const auto& [reason, count] : given.refused) {
    std::printf("    refused: %d images: %s\n", count, reason.c_str());
  }
}

}  // namespace auvdock::cli
