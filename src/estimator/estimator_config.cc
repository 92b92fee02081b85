#include "auvdock/estimator/estimator_config.h"

#include "auvdock/io/yaml_config.h"

namespace auvdock {

RunConfig LoadRunConfig(const std::string& path) {
  const ConfigNode root = ConfigNode::LoadFile(path);
  RunConfig config;
  EstimatorOptions& e = config.estimator;
  const ConfigNode est = root.ChildOrEmpty("estimator");
  e.window_size = est.GetInt("window_size", e.window_size);
  if (e.window_size < 2) est.Fail("window_size", "must be at least 2");
  e.max_solver_iterations = est.GetInt("max_solver_iterations", e.max_solver_iterations);
  if (e.max_solver_iterations < 1) est.Fail("max_solver_iterations", "must be at least 1");
  e.max_solver_time_s = est.GetNonNegative("max_solver_time_s", e.max_solver_time_s);
  e.solver_cost_tolerance = est.GetNonNegative("solver_cost_tolerance", e.solver_cost_tolerance);
  e.chain_solver = est.GetBool("chain_solver", e.chain_solver);
  e.solver_initial_damping =
      est.GetPositive("solver_initial_damping", e.solver_initial_damping);
  e.vision.huber_sigmas = est.GetPositive("huber_sigmas", e.vision.huber_sigmas);
  e.mono_gate_chi2 = est.GetNonNegative("mono_gate_chi2", e.mono_gate_chi2);
  e.stereo_gate_chi2 = est.GetNonNegative("stereo_gate_chi2", e.stereo_gate_chi2);
  e.max_imu_gap_s = est.GetPositive("max_imu_gap_s", e.max_imu_gap_s);
  e.imu_noise_scale = est.GetPositive("imu_noise_scale", e.imu_noise_scale);
  e.vision.use_mono = est.GetBool("use_mono", e.vision.use_mono);
  e.use_depth = est.GetBool("use_depth", e.use_depth);
  e.depth_gate_chi2 = est.GetNonNegative("depth_gate_chi2", e.depth_gate_chi2);
  e.estimate_depth_offset = est.GetBool("estimate_depth_offset", e.estimate_depth_offset);
  e.depth_offset_prior_sigma_m =
      est.GetPositive("depth_offset_prior_sigma_m", e.depth_offset_prior_sigma_m);
  e.depth_offset_random_walk =
      est.GetPositive("depth_offset_random_walk", e.depth_offset_random_walk);
  e.use_dvl = est.GetBool("use_dvl", e.use_dvl);
  e.dvl_gate_chi2 = est.GetNonNegative("dvl_gate_chi2", e.dvl_gate_chi2);
  e.estimate_dvl_bias = est.GetBool("estimate_dvl_bias", e.estimate_dvl_bias);
  e.dvl_bias_prior_sigma_mps =
      est.GetPositive("dvl_bias_prior_sigma_mps", e.dvl_bias_prior_sigma_mps);
  e.dvl_bias_random_walk = est.GetPositive("dvl_bias_random_walk", e.dvl_bias_random_walk);
  e.use_usbl = est.GetBool("use_usbl", e.use_usbl);
  e.usbl_gate_chi2 = est.GetNonNegative("usbl_gate_chi2", e.usbl_gate_chi2);
  e.usbl_rate_test.enabled = est.GetBool("usbl_rate_test", e.usbl_rate_test.enabled);
  e.usbl_rate_test.max_speed_mps =
      est.GetPositive("usbl_rate_max_speed_mps", e.usbl_rate_test.max_speed_mps);
  e.divergence_fixes = est.GetInt("divergence_fixes", e.divergence_fixes);
  if (e.divergence_fixes < 0) est.Fail("divergence_fixes", "must not be negative");
  e.divergence_gated_share = est.GetPositive("divergence_gated_share", e.divergence_gated_share);
  if (e.divergence_gated_share > 1.0) est.Fail("divergence_gated_share", "must be at most 1");
  e.usbl_rate_test.speed_margin_mps =
      est.GetNonNegative("usbl_rate_speed_margin_mps", e.usbl_rate_test.speed_margin_mps);
  e.usbl_max_backward_shift_s =
      est.GetNonNegative("usbl_max_backward_shift_s", e.usbl_max_backward_shift_s);
  e.use_sbl = est.GetBool("use_sbl", e.use_sbl);
  e.sbl_gate_chi2 = est.GetNonNegative("sbl_gate_chi2", e.sbl_gate_chi2);
  e.sbl_rate_test = est.GetBool("sbl_rate_test", e.sbl_rate_test);
  e.sensor_huber_sigmas = est.GetPositive("sensor_huber_sigmas", e.sensor_huber_sigmas);
  e.dvl_rate_test.enabled = est.GetBool("dvl_rate_test", e.dvl_rate_test.enabled);
  e.dvl_rate_test.gate_chi2 = est.GetPositive("dvl_rate_gate_chi2", e.dvl_rate_test.gate_chi2);
  e.dvl_rate_test.accel_sigma_mps2 =
      est.GetPositive("dvl_rate_accel_sigma_mps2", e.dvl_rate_test.accel_sigma_mps2);
  e.dvl_rate_test.max_reference_age_s =
      est.GetPositive("dvl_rate_max_reference_age_s", e.dvl_rate_test.max_reference_age_s);
  e.dvl_admission = est.GetBool("dvl_admission", e.dvl_admission);
  e.dvl_admission_bias_mps = est.GetPositive("dvl_admission_bias_mps", e.dvl_admission_bias_mps);
  e.use_heading = est.GetBool("use_heading", e.use_heading);
  e.heading_gate_chi2 = est.GetNonNegative("heading_gate_chi2", e.heading_gate_chi2);
  e.acoustic_init.enabled = est.GetBool("acoustic_init", e.acoustic_init.enabled);
  e.acoustic_init.min_fixes = est.GetInt("acoustic_init_min_fixes", e.acoustic_init.min_fixes);
  if (e.acoustic_init.min_fixes < 3) est.Fail("acoustic_init_min_fixes", "must be at least 3");
  e.acoustic_init.min_fixes_with_heading = est.GetInt("acoustic_init_min_fixes_with_heading",
                                                      e.acoustic_init.min_fixes_with_heading);
  if (e.acoustic_init.min_fixes_with_heading < 1) {
    est.Fail("acoustic_init_min_fixes_with_heading", "must be at least 1");
  }
  e.acoustic_init.unconfirmed_fix_sigma_m = est.GetPositive(
      "acoustic_init_unconfirmed_fix_sigma_m", e.acoustic_init.unconfirmed_fix_sigma_m);
  e.acoustic_init.max_span_s = est.GetPositive("acoustic_init_max_span_s", e.acoustic_init.max_span_s);
  e.acoustic_init.max_heading_sigma_rad = est.GetPositive(
      "acoustic_init_max_heading_sigma_rad", e.acoustic_init.max_heading_sigma_rad);
  e.vision.use_stereo = est.GetBool("use_stereo", e.vision.use_stereo);
  e.adaptive_vision_noise.enabled =
      est.GetBool("adaptive_vision_noise", e.adaptive_vision_noise.enabled);
  e.adaptive_dvl_noise.enabled = est.GetBool("adaptive_dvl_noise", e.adaptive_dvl_noise.enabled);
  e.adaptive_depth_noise.enabled =
      est.GetBool("adaptive_depth_noise", e.adaptive_depth_noise.enabled);
  e.adaptive_sbl_noise.enabled = est.GetBool("adaptive_sbl_noise", e.adaptive_sbl_noise.enabled);
  e.innovation_outlier_gates =
      est.GetNonNegative("innovation_outlier_gates", e.innovation_outlier_gates);
  e.vision.stereo_covariance_at_prediction =
      est.GetBool("stereo_covariance_at_prediction", e.vision.stereo_covariance_at_prediction);
  const std::string weighting = est.GetString("stage_weighting", "information");
  if (!ParseStageWeightingMode(weighting, &e.vision.stage_weighting.mode)) {
    est.Fail("stage_weighting",
             "expected information or paper_light_count (got '" + weighting + "')");
  }
  e.vision.stage_weighting.min_share =
      est.GetNonNegative("stage_min_share", e.vision.stage_weighting.min_share);
  if (e.vision.stage_weighting.min_share > 0.5) est.Fail("stage_min_share", "must be at most 0.5");
  e.init_position_sigma_m = est.GetPositive("init_position_sigma_m", e.init_position_sigma_m);
  e.init_attitude_sigma_rad = est.GetPositive("init_attitude_sigma_rad", e.init_attitude_sigma_rad);
  e.init_velocity_sigma_mps = est.GetPositive("init_velocity_sigma_mps", e.init_velocity_sigma_mps);
  e.init_gyro_bias_sigma = est.GetPositive("init_gyro_bias_sigma", e.init_gyro_bias_sigma);
  e.init_accel_bias_sigma = est.GetPositive("init_accel_bias_sigma", e.init_accel_bias_sigma);
  e.init_max_tilt_error_rad =
      est.GetNonNegative("init_max_tilt_error_rad", e.init_max_tilt_error_rad);
  e.init_tilt_window_s = est.GetPositive("init_tilt_window_s", e.init_tilt_window_s);
  e.smoother_vision_floor_px =
      est.GetNonNegative("smoother_vision_floor_px", e.smoother_vision_floor_px);
  e.smoother_vision_correlation_time_s = est.GetNonNegative("smoother_vision_correlation_time_s",
                                                            e.smoother_vision_correlation_time_s);
  e.window_vision_floor_px = est.GetNonNegative("window_vision_floor_px", e.window_vision_floor_px);
  e.adaptive_vision_floor.enabled =
      est.GetBool("adaptive_vision_floor", e.adaptive_vision_floor.enabled);
  e.max_window_vision_floor_px =
      est.GetNonNegative("max_window_vision_floor_px", e.max_window_vision_floor_px);
  e.max_window_vision_correlation_time_s = est.GetNonNegative(
      "max_window_vision_correlation_time_s", e.max_window_vision_correlation_time_s);
  e.window_vision_correlation_time_s = est.GetNonNegative("window_vision_correlation_time_s",
                                                          e.window_vision_correlation_time_s);

  GoNoGoOptions& g = config.go_no_go;
  const ConfigNode go = root.ChildOrEmpty("go_no_go");
  g.allowed_lateral_error_m = go.GetPositive("allowed_lateral_error_m", g.allowed_lateral_error_m);
  g.max_yaw_3sigma_rad = go.GetPositive("max_yaw_3sigma_rad", g.max_yaw_3sigma_rad);
  g.max_vision_age_s = go.GetPositive("max_vision_age_s", g.max_vision_age_s);
  g.max_dvl_age_s = go.GetPositive("max_dvl_age_s", g.max_dvl_age_s);
  g.max_aided_vision_age_s = go.GetPositive("max_aided_vision_age_s", g.max_aided_vision_age_s);
  g.max_gating_rate = go.GetNonNegative("max_gating_rate", g.max_gating_rate);
  g.max_depth_gating_rate = go.GetNonNegative("max_depth_gating_rate", g.max_depth_gating_rate);
  g.min_depth_samples = go.GetInt("min_depth_samples", g.min_depth_samples);
  g.gating_window_frames = go.GetInt("gating_window_frames", g.gating_window_frames);
  if (g.gating_window_frames < 1) go.Fail("gating_window_frames", "must be at least 1");
  root.CheckNoUnknownKeys();
  return config;
}

}  // namespace auvdock
