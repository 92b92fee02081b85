#include "auvdock/estimator/sliding_window_estimator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <utility>

#include <Eigen/Eigenvalues>
#include <ceres/iteration_callback.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include "auvdock/estimator/chain_marginals.h"
#include "auvdock/estimator/chain_solver.h"
#include "auvdock/estimator/marginal_covariance.h"
#include "auvdock/estimator/marginalization.h"
#include "auvdock/estimator/sensor_factors.h"
#include "factors/bias_prior_factor.h"
#include "factors/depth_offset_factor.h"
#include "factors/dvl_factor.h"
#include "factors/imu_preintegration_factor.h"
#include "factors/marginalization_factor.h"
#include "factors/pose_manifold.h"
#include "factors/pose_prior_factor.h"
#include "factors/scalar_random_walk_factor.h"
#include "factors/vector_random_walk_factor.h"
#include "factors/velocity_prior_factor.h"

namespace auvdock {
namespace {

constexpr double kNsPerSecond = 1e9;

double Seconds(int64_t ns) { return static_cast<double>(ns) / kNsPerSecond; }

// Ends a solve once a successful step lowered the cost by less than an absolute amount
// (EstimatorOptions::solver_cost_tolerance); Ceres keeps that step's values.
class AbsoluteCostChangeStop : public ceres::IterationCallback {
 public:
  explicit AbsoluteCostChangeStop(double tolerance) : tolerance_(tolerance) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& iteration) override {
    const bool converged = iteration.iteration > 0 && iteration.step_is_successful &&
                           iteration.cost_change < tolerance_;
    return converged ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

 private:
  double tolerance_;
};

}  // namespace

struct SlidingWindowEstimator::State {
  int64_t t_ns = 0;
  double pose[kPoseSize] = {0, 0, 0, 0, 0, 0, 1};
  double velocity[kVelocitySize] = {0, 0, 0};
  double bias[kBiasSize] = {0, 0, 0, 0, 0, 0};
  double depth_offset[kDepthOffsetSize] = {0};  // m; a block only with estimate_depth_offset
  double dvl_bias[kDvlBiasSize] = {0, 0, 0};    // m/s in S; a block only with estimate_dvl_bias
  std::vector<VisionResidual> vision;  // this frame's vision residuals still in the problem
  int n_gated = 0;

  StateRecord Record() const {
    StateRecord record;
    record.t_ns = t_ns;
    std::copy(pose, pose + kPoseSize, record.pose);
    std::copy(velocity, velocity + kVelocitySize, record.velocity);
    std::copy(bias, bias + kBiasSize, record.bias);
    record.depth_offset = depth_offset[0];
    std::copy(dvl_bias, dvl_bias + kDvlBiasSize, record.dvl_bias);
    return record;
  }
};

SlidingWindowEstimator::SlidingWindowEstimator(const Calibration& calibration,
                                               const DockModel& dock,
                                               const EstimatorOptions& options)
    : calibration_(calibration),
      dock_(dock),
      options_(options),
      pose_manifold_(std::make_unique<PoseManifold>()),
      imu_(calibration.imu ? *calibration.imu : ImuCalibration(), options.max_imu_gap_s,
           options.imu_noise_scale),
      dvl_rate_test_(calibration.dvl ? *calibration.dvl : DvlCalibration(),
                     options.dvl_rate_test),
      dvl_noise_(options.adaptive_dvl_noise),
      depth_noise_(options.adaptive_depth_noise),
      sbl_noise_(options.adaptive_sbl_noise),
      slow_vision_error_(options.adaptive_vision_floor),
      usbl_rate_test_(options.usbl_rate_test),
      acoustic_init_(calibration, dock, options.acoustic_init) {
  stats_.window_vision_floor_px = WindowVisionFloorPx();
  stats_.window_vision_correlation_time_s = WindowVisionCorrelationTimeS();
  // An outlier's sample is kept out of the noise statistics (second_difference.h).
  SecondDifferenceOptions depth_innovation = options.depth_innovation;
  depth_innovation.outlier_cutoff = options.innovation_outlier_gates * options.depth_gate_chi2;
  depth_innovation_ = SecondDifference(depth_innovation);
  if (calibration_.sbl) {
    UsblRateTestOptions sbl_rate = options.usbl_rate_test;
    sbl_rate.enabled = options.sbl_rate_test;
    const size_t n_transducers = calibration_.sbl->p_B_transducers.size();
    sbl_rate_tests_.assign(n_transducers, UsblRateTest(sbl_rate));
    SecondDifferenceOptions sbl_innovation = options.sbl_range_innovation;
    sbl_innovation.outlier_cutoff = options.innovation_outlier_gates * options.sbl_gate_chi2;
    sbl_innovations_.assign(n_transducers, SecondDifference(sbl_innovation));
  }
  if (options_.window_size < 2 || options_.max_solver_iterations < 1 ||
      !(options_.vision.huber_sigmas > 0.0) || !(options_.max_imu_gap_s > 0.0) ||
      options_.mono_gate_chi2 < 0.0 || options_.stereo_gate_chi2 < 0.0 ||
      !(options_.init_position_sigma_m > 0.0) || !(options_.init_attitude_sigma_rad > 0.0) ||
      !(options_.init_velocity_sigma_mps > 0.0) || !(options_.init_gyro_bias_sigma > 0.0) ||
      !(options_.init_accel_bias_sigma > 0.0) ||
      (options_.estimate_depth_offset && (!(options_.depth_offset_prior_sigma_m > 0.0) ||
                                          !(options_.depth_offset_random_walk > 0.0))) ||
      (options_.estimate_dvl_bias &&
       (!(options_.dvl_bias_prior_sigma_mps > 0.0) || !(options_.dvl_bias_random_walk > 0.0)))) {
    throw std::invalid_argument("EstimatorOptions: a size, sigma or gate is out of range");
  }
  if (!calibration_.imu) {
    throw std::invalid_argument("SlidingWindowEstimator: the calibration has no IMU");
  }
  rig_.stereo_left = calibration_.FindCameraByRole(CameraRole::kStereoLeft);
  rig_.stereo_right = calibration_.FindCameraByRole(CameraRole::kStereoRight);
  rig_.mono = calibration_.FindCameraByRole(CameraRole::kMono);
  rig_.dock = &dock_;
  depth_offset_on_ = EstimatesDepthOffset(options_, calibration_);
  dvl_bias_on_ = EstimatesDvlBias(options_, calibration_);
  earth_rate_D_ = EarthRate_D(dock_);
  Reset("");
  stats_.resets = 0;
  stats_.log.clear();
}

SlidingWindowEstimator::~SlidingWindowEstimator() = default;

void SlidingWindowEstimator::Reset(const std::string& reason) {
  // The dropped states keep their last estimate in the history (the batch smoother's start).
  for (const auto& state : window_) history_.push_back(state->Record());
  window_.clear();
  symmetry_unresolved_ = false;
  if (calibration_.dvl) {
    if (const std::optional<DvlMeasurement> held =
            dvl_rate_test_.ExpireHeld(std::numeric_limits<int64_t>::max())) {
      ++stats_.dvl_rate_rejected;
      rejections_.push_back({held->t_ns, calibration_.dvl->name, kNoStatistic,
                             "rate test: held, and the estimator was reset (" + reason + ")"});
    }
  }
  dvl_rate_test_.Reset();
  dvl_admitted_ = false;
  recent_fix_gated_.clear();
  newest_pose_velocity_covariance_.reset();
  newest_depth_offset_variance_.reset();
  sbl_transducer_of_.clear();
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.enable_fast_removal = true;
  problem_ = std::make_unique<ceres::Problem>(problem_options);
  if (!reason.empty()) {
    ++stats_.resets;
    stats_.log.push_back("reset: " + reason);
  }
}

void SlidingWindowEstimator::AddImu(const ImuSample& sample) {
  const std::string problem = imu_.Add(sample);
  if (!problem.empty()) {
    ++stats_.skipped_imu;
    stats_.log.push_back("imu sample at " + std::to_string(sample.t_ns) + " ns " + problem +
                         ": skipped");
    return;
  }
  ++stats_.imu_samples;
  // Keep what the oldest state's interval needs (or the last second before initialisation),
  // what the DVL's rate test needs back to its oldest reference,
  const int64_t rate_test_ns =
      sample.t_ns - static_cast<int64_t>((options_.dvl_rate_test.max_reference_age_s + 0.5) *
                                         kNsPerSecond);
  // and what a late fix needs back to the oldest state.
  const int64_t late_fix_ns =
      window_.empty() ? 0
                      : window_.front()->t_ns -
                            static_cast<int64_t>(options_.usbl_max_backward_shift_s * kNsPerSecond);
  // The acoustic start traces the path over its span: before initialisation, and after a reset
  // (a divergence restarts from the fixes), so its span is kept all along (a binary search
  // finds an interval's first sample: a longer buffer costs no time).
  const double history_s = options_.acoustic_init.enabled ? acoustic_init_.imu_history_s() : 1.0;
  const int64_t history_ns = sample.t_ns - static_cast<int64_t>(history_s * kNsPerSecond);
  imu_.DropBefore(window_.empty()
                      ? history_ns
                      : std::min({window_.front()->t_ns, rate_test_ns, late_fix_ns,
                                  options_.acoustic_init.enabled ? history_ns : INT64_MAX}));
}

std::string SlidingWindowEstimator::TiltRefusal(const VisionFrame& frame) const {
  if (!(options_.init_max_tilt_error_rad > 0.0)) return {};
  const int64_t window_ns = static_cast<int64_t>(options_.init_tilt_window_s * 1e9);
  const std::optional<Eigen::Vector3d> f_B =
      imu_.MeanAccel(frame.t_ns - window_ns, frame.t_ns, /*min_samples=*/3);
  const Eigen::Vector3d expected_B = -(frame.T_D_B_initial->q.conjugate() * dock_.gravity_D);
  if (!f_B || !(f_B->norm() > 0.0) || !(expected_B.norm() > 0.0)) return {};
  const double angle = std::atan2(f_B->cross(expected_B).norm(), f_B->dot(expected_B));
  if (angle <= options_.init_max_tilt_error_rad) return {};
  char text[160];
  std::snprintf(text, sizeof(text),
                "first pose refused: its tilt disagrees with the accelerometer by %.1f deg "
                "(at most %.1f)",
                angle * 180.0 / M_PI, options_.init_max_tilt_error_rad * 180.0 / M_PI);
  return text;
}

bool SlidingWindowEstimator::Initialize(const VisionFrame& frame) {
  if (!frame.T_D_B_initial) return false;
  if (const std::string refusal = TiltRefusal(frame); !refusal.empty()) {
    ++stats_.init_refused;
    init_refusal_ = refusal;
    if (stats_.init_refused == 1) {
      stats_.log.push_back(refusal + " at " + std::to_string(frame.t_ns) +
                           " ns (further refusals are counted in init_refused)");
    }
    return false;
  }
  init_refusal_.clear();
  symmetry_unresolved_ = frame.symmetry_unresolved;
  InitialState initial;
  initial.t_ns = frame.t_ns;
  initial.T_D_B = *frame.T_D_B_initial;
  initial.pose_covariance.setZero();
  initial.pose_covariance.topLeftCorner<3, 3>().diagonal().setConstant(
      std::pow(options_.init_position_sigma_m, 2));
  initial.pose_covariance.bottomRightCorner<3, 3>().diagonal().setConstant(
      std::pow(options_.init_attitude_sigma_rad, 2));
  initial.velocity_covariance =
      Eigen::Matrix3d::Identity() * std::pow(options_.init_velocity_sigma_mps, 2);
  StartWindow(initial);
  return true;
}

bool SlidingWindowEstimator::InitializeFromGivenStart(int64_t t_ns) {
  if (!given_start_ || t_ns < given_start_->t_ns) return false;
  InitialState start = *given_start_;
  const int64_t given_t_ns = start.t_ns;
  if (given_t_ns != 0 && given_t_ns != t_ns) {
    // Carried by the IMU from its time to the frame's (zero bias: the bias priors hold it).
    const std::optional<ImuPreintegration> pim = imu_.Preintegrate(given_t_ns, t_ns, ImuBias());
    if (!pim) {
      init_refusal_ = "the given start's time is not covered by the IMU up to the first state";
      return false;
    }
    NavState nav;
    nav.q_D_B = start.T_D_B.q;
    nav.p_D = start.T_D_B.p;
    nav.v_D = start.v_D;
    const NavState at_frame = pim->Predict(nav, ImuBias(), dock_.gravity_D, earth_rate_D_);
    start.T_D_B = Pose3(at_frame.q_D_B, at_frame.p_D);
    start.v_D = at_frame.v_D;
  }
  start.t_ns = t_ns;
  init_refusal_.clear();
  given_start_.reset();
  applied_start_ = start;
  stats_.log.push_back("start from the given state at " + std::to_string(t_ns) + " ns");
  StartWindow(start);
  // The user vouches for the state (an INS's output, a survey): the DVL is tested against it by
  // the gate from the first sample, as after the acoustic start's fit, not held out until the
  // window's own velocity could see a gross bias (with a navigator's velocity sigma of a few
  // cm/s that never comes without the DVL itself, and the IMU alone then drifts away).
  dvl_admitted_ = true;
  return true;
}

bool SlidingWindowEstimator::InitializeAcoustically(int64_t t_ns) {
  if (!options_.acoustic_init.enabled || !acoustic_init_.has_new_data()) return false;
  std::string why;
  const std::optional<InitialState> initial = acoustic_init_.Solve(imu_, t_ns, &why);
  if (!initial) {
    init_refusal_ = why;
    return false;
  }
  init_refusal_.clear();
  symmetry_unresolved_ = false;
  ++stats_.acoustic_starts;
  char text[200];
  std::snprintf(text, sizeof(text),
                "acoustic start at %lld ns: %d fixes (%d left out%s), heading %s to %.1f deg",
                static_cast<long long>(t_ns), initial->fixes_used, initial->fixes_rejected,
                initial->unconfirmed ? "; unconfirmed: sigma widened to an outlier's size" : "",
                initial->heading_measured ? "measured" : "from the path",
                initial->heading_sigma_rad * 180.0 / M_PI);
  stats_.log.push_back(text);
  // The fixes and DVL samples up to now are in the start's prior: not used twice.
  const auto before = [&](const auto& sample) { return sample.t_ns <= t_ns; };
  pending_usbl_.erase(std::remove_if(pending_usbl_.begin(), pending_usbl_.end(), before),
                      pending_usbl_.end());
  pending_dvl_.erase(std::remove_if(pending_dvl_.begin(), pending_dvl_.end(), before),
                     pending_dvl_.end());
  StartWindow(*initial);
  dvl_admitted_ = true;  // the start's fit checked the DVL's path against the fixes
  return true;
}

void SlidingWindowEstimator::StartWindow(const InitialState& initial) {
  auto state = std::make_unique<State>();
  state->t_ns = initial.t_ns;
  first_state_t_ns_ = initial.t_ns;
  PoseToBlock(initial.T_D_B, state->pose);
  std::copy(initial.v_D.data(), initial.v_D.data() + 3, state->velocity);
  problem_->AddParameterBlock(state->pose, kPoseSize, pose_manifold_.get());
  problem_->AddParameterBlock(state->velocity, kVelocitySize);
  problem_->AddParameterBlock(state->bias, kBiasSize);
  problem_->AddResidualBlock(PosePriorFactor::Create(initial.T_D_B, initial.pose_covariance),
                             nullptr, state->pose);
  problem_->AddResidualBlock(VelocityPriorFactor::Create(initial.v_D, initial.velocity_covariance),
                             nullptr, state->velocity);
  Matrix6d bias_cov = Matrix6d::Zero();
  bias_cov.topLeftCorner<3, 3>().diagonal().setConstant(std::pow(options_.init_gyro_bias_sigma, 2));
  bias_cov.bottomRightCorner<3, 3>().diagonal().setConstant(
      std::pow(options_.init_accel_bias_sigma, 2));
  problem_->AddResidualBlock(BiasPriorFactor::Create(Eigen::Matrix<double, 6, 1>::Zero(), bias_cov),
                             nullptr, state->bias);
  newest_accel_uncertainty_mps2_ = AccelUncertainty(initial.pose_covariance.block<3, 3>(3, 3),
                                                    bias_cov.bottomRightCorner<3, 3>());
  if (dvl_bias_on_) {
    problem_->AddParameterBlock(state->dvl_bias, kDvlBiasSize);
    problem_->AddResidualBlock(
        VectorPriorFactor::Create(Eigen::Vector3d::Zero(), options_.dvl_bias_prior_sigma_mps),
        nullptr, state->dvl_bias);
  }
  if (depth_offset_on_) {
    problem_->AddParameterBlock(state->depth_offset, kDepthOffsetSize);
    problem_->AddResidualBlock(
        ScalarPriorFactor::Create(0.0, options_.depth_offset_prior_sigma_m), nullptr,
        state->depth_offset);
  }
  window_.push_back(std::move(state));
}

bool SlidingWindowEstimator::AddState(int64_t t_ns) {
  State& previous = *window_.back();
  const ImuBias bias = BiasFromBlock(previous.bias);
  const std::optional<ImuPreintegration> pim = imu_.Preintegrate(previous.t_ns, t_ns, bias);
  if (!pim) return false;

  auto state = std::make_unique<State>();
  state->t_ns = t_ns;
  NavState nav;
  const Pose3 previous_pose = PoseFromBlock(previous.pose);
  nav.q_D_B = previous_pose.q;
  nav.p_D = previous_pose.p;
  nav.v_D = Eigen::Map<const Eigen::Vector3d>(previous.velocity);
  const NavState predicted = pim->Predict(nav, bias, dock_.gravity_D, earth_rate_D_);
  PoseToBlock(Pose3(predicted.q_D_B, predicted.p_D), state->pose);
  Eigen::Map<Eigen::Vector3d>(state->velocity) = predicted.v_D;
  std::copy(previous.bias, previous.bias + kBiasSize, state->bias);

  problem_->AddParameterBlock(state->pose, kPoseSize, pose_manifold_.get());
  problem_->AddParameterBlock(state->velocity, kVelocitySize);
  problem_->AddParameterBlock(state->bias, kBiasSize);
  problem_->AddResidualBlock(ImuPreintegrationFactor::Create(*pim, dock_.gravity_D, earth_rate_D_),
                             nullptr, previous.pose, previous.velocity, previous.bias, state->pose,
                             state->velocity, state->bias);
  if (dvl_bias_on_) {
    std::copy(previous.dvl_bias, previous.dvl_bias + kDvlBiasSize, state->dvl_bias);
    problem_->AddParameterBlock(state->dvl_bias, kDvlBiasSize);
    problem_->AddResidualBlock(VectorRandomWalkFactor::Create(options_.dvl_bias_random_walk,
                                                              Seconds(t_ns - previous.t_ns)),
                               nullptr, previous.dvl_bias, state->dvl_bias);
  }
  if (depth_offset_on_) {
    state->depth_offset[0] = previous.depth_offset[0];
    problem_->AddParameterBlock(state->depth_offset, kDepthOffsetSize);
    problem_->AddResidualBlock(
        ScalarRandomWalkFactor::Create(options_.depth_offset_random_walk,
                                       Seconds(t_ns - previous.t_ns)),
        nullptr, previous.depth_offset, state->depth_offset);
  }
  window_.push_back(std::move(state));
  return true;
}

bool SlidingWindowEstimator::Solve(bool stop_early) {
  if (options_.chain_solver) {
    ChainSolverOptions chain;
    chain.max_iterations = options_.max_solver_iterations;
    chain.max_time_s = options_.max_solver_time_s;
    chain.initial_lambda = options_.solver_initial_damping;
    if (stop_early) chain.cost_change_tolerance = options_.solver_cost_tolerance;
    const std::optional<ChainSolverSummary> summary =
        SolveChain(problem_.get(), StateBlocksInOrder(), chain);
    if (summary) return summary->usable;  // else not a chain: Ceres below
  }
  ceres::Solver::Options options;
  // The same first damping as the chain solver's (Ceres' trust region radius is its inverse).
  options.initial_trust_region_radius = 1.0 / options_.solver_initial_damping;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  options.max_num_iterations = options_.max_solver_iterations;
  if (options_.max_solver_time_s > 0.0) {
    options.max_solver_time_in_seconds = options_.max_solver_time_s;
  }
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  AbsoluteCostChangeStop stop(options_.solver_cost_tolerance);
  if (stop_early && options_.solver_cost_tolerance > 0.0) options.callbacks.push_back(&stop);
  ceres::Solver::Summary summary;
  ceres::Solve(options, problem_.get(), &summary);
  if (!summary.IsSolutionUsable() || !std::isfinite(summary.final_cost)) return false;
  for (const auto& state : window_) {
    const bool finite = std::all_of(state->pose, state->pose + kPoseSize,
                                    [](double x) { return std::isfinite(x); }) &&
                        std::all_of(state->velocity, state->velocity + kVelocitySize,
                                    [](double x) { return std::isfinite(x); }) &&
                        std::all_of(state->bias, state->bias + kBiasSize,
                                    [](double x) { return std::isfinite(x); }) &&
                        std::isfinite(state->depth_offset[0]) &&
                        std::all_of(state->dvl_bias, state->dvl_bias + kDvlBiasSize,
                                    [](double x) { return std::isfinite(x); });
    if (!finite) return false;
  }
  return true;
}

void SlidingWindowEstimator::AddDepth(const DepthMeasurement& sample) {
  if (!options_.use_depth || !calibration_.depth) return;
  std::string problem = ImplausibleDepth(sample);
  if (problem.empty() && sample.t_ns <= last_depth_sample_t_ns_) problem = "out of order or repeated";
  if (!problem.empty()) {
    ++stats_.depth_skipped;
    rejections_.push_back({sample.t_ns, calibration_.depth->name, kNoStatistic, problem});
    return;
  }
  last_depth_sample_t_ns_ = sample.t_ns;
  if (const std::optional<double> statistic =
          depth_innovation_.Add(sample.t_ns, sample.depth_m, calibration_.depth->sigma_m,
                                depth_noise_.factor())) {
    depth_noise_.UpdateCensored(*statistic, 1,
                               options_.innovation_outlier_gates * options_.depth_gate_chi2);
    stats_.depth_variance_factor = depth_noise_.factor();
  }
  pending_depth_.push_back(sample);
}

void SlidingWindowEstimator::AddUsbl(const AcousticFix& fix) {
  if (!options_.use_usbl || !calibration_.acoustic) return;
  std::string problem;
  if (!fix.p_D.allFinite() || !std::isfinite(fix.sigma_m) || !(fix.sigma_m > 0.0)) {
    problem = "not finite or no positive sigma";
  } else if (fix.t_ns <= last_usbl_sample_t_ns_) {
    problem = "out of order or repeated";
  }
  if (!problem.empty()) {
    ++stats_.usbl_skipped;
    rejections_.push_back({fix.t_ns, calibration_.acoustic->name, kNoStatistic, problem});
    return;
  }
  last_usbl_sample_t_ns_ = fix.t_ns;
  const UsblRateVerdict verdict = usbl_rate_test_.Check(fix);
  if (!verdict.pass) {
    ++stats_.usbl_rate_rejected;
    rejections_.push_back({fix.t_ns, calibration_.acoustic->name, verdict.excess, verdict.reason});
    return;
  }
  pending_usbl_.push_back(fix);
  if (options_.acoustic_init.enabled) acoustic_init_.AddFix(fix);
}

void SlidingWindowEstimator::AddHeading(const HeadingMeasurement& sample) {
  if (!options_.use_heading || !calibration_.heading) return;
  std::string problem;
  if (!std::isfinite(sample.heading_rad)) {
    problem = "not finite";
  } else if (sample.t_ns <= last_heading_sample_t_ns_) {
    problem = "out of order or repeated";
  }
  if (!problem.empty()) {
    ++stats_.heading_skipped;
    rejections_.push_back({sample.t_ns, calibration_.heading->name, kNoStatistic, problem});
    return;
  }
  last_heading_sample_t_ns_ = sample.t_ns;
  pending_heading_.push_back(sample);
  if (options_.acoustic_init.enabled) acoustic_init_.AddHeading(sample);
}

void SlidingWindowEstimator::AddSblRange(const SblRange& range) {
  if (!options_.use_sbl || !calibration_.sbl) return;
  std::string problem;
  const int n_transducers = static_cast<int>(calibration_.sbl->p_B_transducers.size());
  if (!std::isfinite(range.range_m) || range.range_m < 0.0 || !std::isfinite(range.sigma_m) ||
      !(range.sigma_m > 0.0)) {
    problem = "not finite, negative or no positive sigma";
  } else if (range.transducer < 0 || range.transducer >= n_transducers) {
    problem = "transducer " + std::to_string(range.transducer) + " not in the calibration";
  } else if (range.t_ns < last_sbl_sample_t_ns_ ||
             (range.t_ns == last_sbl_sample_t_ns_ && range.transducer <= last_sbl_transducer_)) {
    problem = "out of order or repeated";
  }
  if (!problem.empty()) {
    ++stats_.sbl_skipped;
    rejections_.push_back({range.t_ns, calibration_.sbl->name, kNoStatistic, problem});
    return;
  }
  last_sbl_sample_t_ns_ = range.t_ns;
  last_sbl_transducer_ = range.transducer;
  const UsblRateVerdict verdict = sbl_rate_tests_[range.transducer].Check(range);
  if (!verdict.pass) {
    ++stats_.sbl_rate_rejected;
    rejections_.push_back({range.t_ns, calibration_.sbl->name, verdict.excess,
                           "transducer " + std::to_string(range.transducer) + ": " +
                               verdict.reason});
    return;
  }
  if (const std::optional<double> statistic = sbl_innovations_[range.transducer].Add(
          range.t_ns, range.range_m, range.sigma_m, sbl_noise_.factor())) {
    sbl_noise_.UpdateCensored(*statistic, 1,
                             options_.innovation_outlier_gates * options_.sbl_gate_chi2);
    stats_.sbl_variance_factor = sbl_noise_.factor();
  }
  pending_sbl_.push_back(range);
}

std::vector<SensorResidual> SlidingWindowEstimator::AttachSbl(int64_t t_ns) {
  if (!calibration_.sbl) return {};
  return AttachPending(&pending_sbl_, t_ns, calibration_.sbl->name, &stats_.sbl_skipped,
                       [&](const SblRange& range, State& state) {
                         const std::optional<ceres::ResidualBlockId> id = AddSblFactor(
                             problem_.get(), range, *calibration_.sbl, dock_, BlocksOf(state),
                             state.t_ns, sbl_noise_.factor(), options_.sensor_huber_sigmas);
                         if (id) sbl_transducer_of_[*id] = range.transducer;
                         return id;
                       });
}

std::vector<SensorResidual> SlidingWindowEstimator::AttachHeading(int64_t t_ns) {
  if (!calibration_.heading) return {};
  return AttachPending(&pending_heading_, t_ns, calibration_.heading->name,
                       &stats_.heading_skipped,
                       [&](const HeadingMeasurement& sample, State& state) {
                         return AddHeadingFactor(problem_.get(), sample, *calibration_.heading,
                                                 dock_, BlocksOf(state), state.t_ns,
                                                 options_.sensor_huber_sigmas);
                       });
}

std::vector<SensorResidual> SlidingWindowEstimator::AttachUsbl(int64_t t_ns) {
  return AttachPending(&pending_usbl_, t_ns, calibration_.acoustic->name, &stats_.usbl_skipped,
                       [&](const AcousticFix& fix, State& state) {
                         return AddUsblFactor(problem_.get(), fix, *calibration_.acoustic, dock_,
                                              BlocksOf(state), state.t_ns,
                                              options_.sensor_huber_sigmas);
                       },
                       options_.usbl_max_backward_shift_s);
}

void SlidingWindowEstimator::AddDvl(const DvlMeasurement& sample) {
  if (!options_.use_dvl || !calibration_.dvl) return;
  if (!sample.v_S.allFinite()) {
    ++stats_.dvl_no_lock;
    return;
  }
  std::string problem = sample.t_ns <= last_dvl_sample_t_ns_ ? "out of order or repeated" : "";
  if (problem.empty()) problem = held_dvl_reading_.Check(sample);
  if (!problem.empty()) {
    ++stats_.dvl_skipped;
    rejections_.push_back({sample.t_ns, calibration_.dvl->name, kNoStatistic, problem});
    return;
  }
  last_dvl_sample_t_ns_ = sample.t_ns;
  if (window_.empty()) {
    // Before a start the acoustic rate tests take the vehicle's speed from the DVL.
    usbl_rate_test_.SetEstimatedSpeed(sample.v_S.norm());
    for (UsblRateTest& test : sbl_rate_tests_) test.SetEstimatedSpeed(sample.v_S.norm());
  }
  pending_dvl_.push_back(sample);
  if (options_.acoustic_init.enabled) acoustic_init_.AddDvl(sample);
}

double SlidingWindowEstimator::AccelUncertainty(const Eigen::Matrix3d& attitude_covariance,
                                                const Eigen::Matrix3d& accel_bias_covariance) const {
  // The tilt: the attitude's rotation about the horizontal axes (dtheta in D), which turns g.
  const Eigen::Vector3d down = dock_.gravity_D.normalized();
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - down * down.transpose();
  const double tilt_variance =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(P * attitude_covariance * P)
          .eigenvalues()
          .maxCoeff();
  const double bias_variance =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(accel_bias_covariance).eigenvalues().maxCoeff();
  const double variance =
      dock_.gravity_D.squaredNorm() * std::max(0.0, tilt_variance) + std::max(0.0, bias_variance);
  return std::isfinite(variance) ? std::sqrt(variance) : 0.0;
}

StateBlocks SlidingWindowEstimator::BlocksOf(State& state) const {
  return StateBlocks(state.pose, state.velocity, &imu_, BiasFromBlock(state.bias),
                     depth_offset_on_ ? state.depth_offset : nullptr,
                     dvl_bias_on_ ? state.dvl_bias : nullptr);
}

SlidingWindowEstimator::State* SlidingWindowEstimator::StateFor(int64_t t_ns,
                                                                double max_before_s) {
  auto it = std::find_if(window_.rbegin(), window_.rend(),
                         [&](const std::unique_ptr<State>& s) { return s->t_ns <= t_ns; });
  if (it != window_.rend()) return it->get();
  if (!window_.empty() && t_ns >= first_state_t_ns_ &&
      window_.front()->t_ns - t_ns <= static_cast<int64_t>(max_before_s * kNsPerSecond)) {
    return window_.front().get();
  }
  return nullptr;
}

template <typename Sample, typename AddFactor>
std::vector<SensorResidual> SlidingWindowEstimator::AttachPending(std::deque<Sample>* pending,
                                                                  int64_t t_ns,
                                                                  const std::string& sensor,
                                                                  int* skipped,
                                                                  const AddFactor& add,
                                                                  double max_before_s) {
  std::vector<SensorResidual> added;
  while (!pending->empty() && pending->front().t_ns <= t_ns) {
    const Sample sample = pending->front();
    pending->pop_front();
    std::optional<ceres::ResidualBlockId> id;
    if (State* state = StateFor(sample.t_ns, max_before_s)) id = add(sample, *state);
    if (id) {
      added.push_back({*id, sample.t_ns});
    } else {
      ++*skipped;
      rejections_.push_back({sample.t_ns, sensor, kNoStatistic,
                             sample.t_ns < first_state_t_ns_ ? kBeforeFirstStateReason
                                                             : kNoStateReason});
    }
  }
  return added;
}

std::vector<SensorResidual> SlidingWindowEstimator::AttachDepth(int64_t t_ns) {
  return AttachPending(&pending_depth_, t_ns, calibration_.depth->name, &stats_.depth_skipped,
                       [&](const DepthMeasurement& sample, State& state) {
                         return AddDepthFactor(problem_.get(), sample, *calibration_.depth, dock_,
                                               BlocksOf(state), state.t_ns, depth_noise_.factor(),
                                               options_.sensor_huber_sigmas);
                       });
}

std::vector<SensorResidual> SlidingWindowEstimator::AttachDvl(int64_t t_ns) {
  std::vector<SensorResidual> added;
  const std::string& name = calibration_.dvl->name;
  const auto reject = [&](int64_t sample_t_ns, double statistic, const std::string& reason) {
    ++stats_.dvl_rate_rejected;
    rejections_.push_back({sample_t_ns, name, statistic, reason});
  };
  // The sample's factor on the state at or before it; shift: the IMU's motion from that state
  // (computed once per sample; nullptr: none needed or available).
  const auto add = [&](const DvlMeasurement& sample, State* state,
                       const ImuPoseShift* shift) {
    std::optional<ceres::ResidualBlockId> id;
    if (state) {
      id = AddDvlFactor(problem_.get(), sample, *calibration_.dvl, dock_, BlocksOf(*state),
                        state->t_ns, shift, dvl_noise_.factor(), options_.sensor_huber_sigmas);
    }
    if (id && !dvl_admitted_) {
      std::string reason;
      const double statistic = DvlAdmissionStatistic(*id, &reason);
      if (!reason.empty() || statistic > options_.dvl_gate_chi2) {
        problem_->RemoveResidualBlock(*id);
        ++stats_.dvl_not_admitted;
        rejections_.push_back({sample.t_ns, name, statistic,  // NaN when untestable
                               reason.empty() ? std::string(kDvlNotAdmittedReason) : reason});
        return;
      }
      dvl_admitted_ = true;
    }
    if (id) {
      added.push_back({*id, sample.t_ns});
    } else {
      ++stats_.dvl_skipped;
      rejections_.push_back({sample.t_ns, name, kNoStatistic, kNoStateReason});
    }
  };
  if (const std::optional<DvlMeasurement> expired = dvl_rate_test_.ExpireHeld(t_ns)) {
    reject(expired->t_ns, kNoStatistic, kHeldDvlExpiredReason);
  }
  while (!pending_dvl_.empty() && pending_dvl_.front().t_ns <= t_ns) {
    const DvlMeasurement sample = pending_dvl_.front();
    pending_dvl_.pop_front();
    State* state = StateFor(sample.t_ns);
    std::optional<ImuPoseShift> shift;
    if (state) {
      const StateBlocks blocks = BlocksOf(*state);
      shift = ImuShiftFromState(blocks, state->t_ns, sample.t_ns - state->t_ns, dock_.gravity_D);
      if (shift) {
        dvl_rate_test_.SetNoiseFactor(dvl_noise_.factor());
        dvl_rate_test_.SetStateUncertainty(newest_accel_uncertainty_mps2_);
        const DvlRateVerdict verdict =
            dvl_rate_test_.Check(sample, imu_, blocks.bias,
                                 PoseFromBlock(state->pose).q * shift->delta_q, dock_.gravity_D);
        if (std::isfinite(verdict.statistic)) {
          dvl_noise_.UpdateCensored(
              verdict.statistic, 3,
              options_.innovation_outlier_gates * options_.dvl_rate_test.gate_chi2);
          stats_.dvl_variance_factor = dvl_noise_.factor();
        }
        if (verdict.dropped) {
          reject(verdict.dropped->t_ns, verdict.statistic, verdict.dropped_reason);
        }
        if (verdict.released) {  // a held sample that this one agrees with, at its own time
          State* earlier = StateFor(verdict.released->t_ns);
          std::optional<ImuPoseShift> earlier_shift;
          if (earlier) {
            earlier_shift = ImuShiftFromState(BlocksOf(*earlier), earlier->t_ns,
                                              verdict.released->t_ns - earlier->t_ns,
                                              dock_.gravity_D);
          }
          add(*verdict.released, earlier, earlier_shift ? &*earlier_shift : nullptr);
        }
        if (verdict.held) continue;
        if (!verdict.pass) {
          reject(sample.t_ns, verdict.statistic, verdict.reason);
          continue;
        }
      }
    }
    // The shift is the one the rate test used: the IMU is preintegrated once per sample.
    add(sample, state, shift ? &*shift : nullptr);
  }
  return added;
}

void SlidingWindowEstimator::MarginalizeOldest() {
  State& oldest = *window_.front();
  history_.push_back(oldest.Record());
  LinearizedPrior prior = MarginalizeOut(problem_.get(), ParameterBlocks(oldest));
  window_.pop_front();
  if (!prior.blocks.empty()) {
    auto* factor = new MarginalizationFactor(std::move(prior));
    problem_->AddResidualBlock(factor, nullptr, factor->parameter_blocks());
  }
}

std::vector<double*> SlidingWindowEstimator::ParameterBlocks(State& state) const {
  std::vector<double*> blocks = {state.pose, state.velocity, state.bias};
  if (dvl_bias_on_) blocks.push_back(state.dvl_bias);
  if (depth_offset_on_) blocks.push_back(state.depth_offset);
  return blocks;
}

std::vector<std::vector<double*>> SlidingWindowEstimator::StateBlocksInOrder() const {
  std::vector<std::vector<double*>> states;
  states.reserve(window_.size());
  for (const auto& s : window_) states.push_back(ParameterBlocks(*s));
  return states;
}

std::optional<Eigen::MatrixXd> SlidingWindowEstimator::PoseCovariance(const State& state,
                                                                      std::string* reason) {
  if (&state != window_.back().get()) {
    return MarginalCovariance(problem_.get(), state.pose, {}, reason);
  }
  // The window is a chain (IMU factors between neighbours, every other factor on one state, the
  // marginalisation prior on the oldest): the forward sweep gives the newest state's marginal.
  const std::optional<LastStateMarginal> last =
      ChainMarginalOfLast(problem_.get(), StateBlocksInOrder());
  if (!last) return MarginalCovariance(problem_.get(), state.pose, {}, reason);
  if (!last->covariance) {
    *reason = "rank-deficient information (an unobserved direction)";
    return std::nullopt;
  }
  newest_pose_velocity_covariance_ =
      last->covariance->topLeftCorner(kPoseTangentSize + kVelocitySize,
                                      kPoseTangentSize + kVelocitySize);
  // The offset block is the state's last (StateBlocksInOrder).
  if (depth_offset_on_) {
    const Eigen::Index k = last->covariance->rows() - 1;
    newest_depth_offset_variance_ = (*last->covariance)(k, k);
  }
  newest_accel_uncertainty_mps2_ = AccelUncertainty(
      last->covariance->block<3, 3>(3, 3),
      last->covariance->block<3, 3>(kPoseTangentSize + kVelocitySize + 3,
                                    kPoseTangentSize + kVelocitySize + 3));
  return last->covariance->topLeftCorner(kPoseTangentSize, kPoseTangentSize).eval();
}

double SlidingWindowEstimator::DvlAdmissionStatistic(ceres::ResidualBlockId id,
                                                     std::string* reason) {
  // Off, no covariance to test with, or no DVL gate (dvl_gate_chi2 0): admitted at once.
  if (!options_.dvl_admission || !options_.compute_covariance || !(options_.dvl_gate_chi2 > 0.0)) {
    return 0.0;
  }
  if (!newest_pose_velocity_covariance_) {
    *reason = kDvlUntestableReason;
    return kNoStatistic;
  }
  std::vector<double*> blocks;
  problem_->GetParameterBlocksForResidualBlock(id, &blocks);
  // The residual's Jacobian on its state's pose (tangent) and velocity, with the newest state's
  // marginal after the last solve (a sample on an older state, a late one, the same).
  Eigen::Vector3d residual = Eigen::Vector3d::Zero();
  std::vector<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> J(blocks.size());
  std::vector<double*> jacobians(blocks.size());
  for (size_t b = 0; b < blocks.size(); ++b) {
    J[b].resize(3, problem_->ParameterBlockTangentSize(blocks[b]));
    jacobians[b] = J[b].data();
  }
  double cost = 0.0;
  if (!problem_->EvaluateResidualBlock(id, /*apply_loss_function=*/false, &cost, residual.data(),
                                       jacobians.data())) {
    *reason = kDvlUntestableReason;
    return kNoStatistic;
  }
  Eigen::Matrix<double, 3, kPoseTangentSize + kVelocitySize> H =
      Eigen::Matrix<double, 3, kPoseTangentSize + kVelocitySize>::Zero();
  // AddDvlFactor's blocks: the pose, the velocity, then the DVL's bias when estimated (its
  // prior's uncertainty is left out: the admission tests for gross errors, beyond the bias's).
  if (blocks.size() >= 2) {
    H.leftCols<kPoseTangentSize>() = J[0];
    H.rightCols<kVelocitySize>() = J[1];
  }
  const Eigen::Matrix3d S =
      Eigen::Matrix3d::Identity() + H * *newest_pose_velocity_covariance_ * H.transpose();
  const double sigma = calibration_.dvl->sigma_mps * std::sqrt(dvl_noise_.factor());
  const double bias_whitened = options_.dvl_admission_bias_mps / sigma;
  const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(S).eigenvalues().maxCoeff();
  if (largest * options_.dvl_gate_chi2 > bias_whitened * bias_whitened) {
    *reason = kDvlUntestableReason;
    return kNoStatistic;
  }
  return residual.dot(S.ldlt().solve(residual));
}

EstimatorOutput SlidingWindowEstimator::Output(const State& state) {
  EstimatorOutput out;
  out.symmetry_unresolved = symmetry_unresolved_;
  out.t_ns = state.t_ns;
  out.T_D_B = PoseFromBlock(state.pose);
  out.v_D = Eigen::Map<const Eigen::Vector3d>(state.velocity);
  out.bias = BiasFromBlock(state.bias);
  if (depth_offset_on_) out.depth_offset_m = state.depth_offset[0];
  for (const VisionResidual& r : state.vision) (r.mono ? out.n_mono : out.n_stereo) += 1;
  out.n_gated = state.n_gated;
  out.seconds_since_vision =
      last_vision_t_ns_ == INT64_MIN ? -1.0 : Seconds(state.t_ns - last_vision_t_ns_);
  // A DVL sample used with this frame may be a little after the state (an unsynchronised clock).
  out.seconds_since_dvl =
      last_dvl_t_ns_ == INT64_MIN ? -1.0 : std::max(0.0, Seconds(state.t_ns - last_dvl_t_ns_));
  if (options_.compute_covariance) {
    std::string reason;
    const std::optional<Eigen::MatrixXd> covariance = PoseCovariance(state, &reason);
    if (covariance) {
      out.covariance = *covariance;
      out.covariance_ok = true;
      if (depth_offset_on_ && newest_depth_offset_variance_ && &state == window_.back().get()) {
        out.depth_offset_sigma_m = std::sqrt(*newest_depth_offset_variance_);
      }
    } else {
      ++stats_.covariance_failures;
      stats_.log.push_back("covariance at " + std::to_string(state.t_ns) + " ns: " + reason +
                           ", not reported");
    }
  }
  if (depth_offset_on_ && &state == window_.back().get()) {
    stats_.depth_offset_m = out.depth_offset_m;
    stats_.depth_offset_sigma_m = out.depth_offset_sigma_m;
  }
  return out;
}

std::optional<EstimatorOutput> SlidingWindowEstimator::AddVisionFrame(const VisionFrame& frame) {
  ++stats_.frames;
  if (frame.t_ns <= last_frame_t_ns_) {
    ++stats_.skipped_frames;
    stats_.log.push_back("frame at " + std::to_string(frame.t_ns) +
                         " ns out of order or repeated: skipped");
    return std::nullopt;
  }
  const double frame_interval_s =
      last_frame_t_ns_ != INT64_MIN ? static_cast<double>(frame.t_ns - last_frame_t_ns_) * 1e-9 : 0.0;
  last_frame_t_ns_ = frame.t_ns;

  if (window_.empty()) {
    if (!InitializeFromGivenStart(frame.t_ns) && !Initialize(frame) &&
        !InitializeAcoustically(frame.t_ns)) {
      return std::nullopt;
    }
  } else if (!AddState(frame.t_ns)) {
    // One reset per outage: while no IMU sample has come since the last reset for a gap, the
    // window restarts at each frame of the outage without counting it again.
    const bool same_outage = imu_.newest_t_ns() == imu_outage_newest_t_ns_;
    Reset(same_outage ? std::string()
                      : "no IMU coverage (gap longer than " +
                            std::to_string(options_.max_imu_gap_s) + " s) up to " +
                            std::to_string(frame.t_ns) + " ns");
    imu_outage_newest_t_ns_ = imu_.newest_t_ns();
    if (!InitializeFromGivenStart(frame.t_ns) && !Initialize(frame) &&
        !InitializeAcoustically(frame.t_ns)) {
      return std::nullopt;
    }
  }
  State* state = window_.back().get();
  VisionFactorOptions vision = options_.vision;
  for (const auto& [id, scale] : mono_noise_) vision.mono_variance_factor[id] = scale.factor();
  for (const auto& [id, scale] : stereo_noise_) vision.stereo_variance_factor[id] = scale.factor();
  vision.correlated_pixel_variance = CorrelatedVisionVariance(
      WindowVisionFloorPx(), WindowVisionCorrelationTimeS(), frame_interval_s);
  state->vision = AddVisionFactors(problem_.get(), frame, rig_, vision,
                                   StateBlocks(state->pose, state->velocity, &imu_,
                                               BiasFromBlock(state->bias)),
                                   &stats_.skipped_observations);
  std::vector<SensorResidual> depth = AttachDepth(frame.t_ns);
  std::vector<SensorResidual> dvl = AttachDvl(frame.t_ns);
  std::vector<SensorResidual> usbl = AttachUsbl(frame.t_ns);
  std::vector<SensorResidual> sbl = AttachSbl(frame.t_ns);
  std::vector<SensorResidual> heading = AttachHeading(frame.t_ns);

  if (!Solve()) {
    ++stats_.solver_failures;
    Reset("solver failed at " + std::to_string(frame.t_ns) + " ns");
    return std::nullopt;
  }
  state->n_gated = GateVisionResiduals(problem_.get(), options_.mono_gate_chi2,
                                       options_.stereo_gate_chi2, &state->vision, &rejections_);
  if (frame_interval_s > 0.0) {
    slow_vision_error_.Add(*problem_, state->vision,
                           static_cast<int64_t>(1.5e9 * frame_interval_s));
    stats_.window_vision_floor_px = WindowVisionFloorPx();
    stats_.window_vision_correlation_time_s = WindowVisionCorrelationTimeS();
  }
  // One sensor's residuals through its gate, counted (sensor: its calibration, present whenever
  // it has residuals).
  const auto gate = [&](std::vector<SensorResidual>* residuals, double gate_chi2,
                        const auto& sensor, int* gated, int* used) {
    const int n = residuals->empty() ? 0
                                     : GateSensorResiduals(problem_.get(), gate_chi2, sensor->name,
                                                           residuals, &rejections_);
    *gated += n;
    *used += static_cast<int>(residuals->size());
    return n;
  };
  const int depth_gated = gate(&depth, options_.depth_gate_chi2, calibration_.depth,
                               &stats_.depth_gated, &stats_.depth_used);
  const int dvl_gated =
      gate(&dvl, options_.dvl_gate_chi2, calibration_.dvl, &stats_.dvl_gated, &stats_.dvl_used);
  const int usbl_gated = gate(&usbl, options_.usbl_gate_chi2, calibration_.acoustic,
                              &stats_.usbl_gated, &stats_.usbl_used);
  const int heading_gated = gate(&heading, options_.heading_gate_chi2, calibration_.heading,
                                 &stats_.heading_gated, &stats_.heading_used);
  const int sbl_gated = gate(&sbl, options_.sbl_gate_chi2, calibration_.sbl, &stats_.sbl_gated,
                             &stats_.sbl_used);
  for (const SensorResidual& kept : usbl) usbl_rate_test_.Confirm(kept.t_ns);
  for (const SensorResidual& kept : sbl) {
    sbl_rate_tests_[sbl_transducer_of_.at(kept.id)].Confirm(kept.t_ns);
  }
  sbl_transducer_of_.clear();
  for (const SensorResidual& kept : dvl) {
    dvl_rate_test_.Confirm(kept.t_ns);
    last_dvl_t_ns_ = std::max(last_dvl_t_ns_, kept.t_ns);
  }
  const bool any_gated = state->n_gated > 0 || depth_gated > 0 || dvl_gated > 0 ||
                         usbl_gated > 0 || sbl_gated > 0 || heading_gated > 0;
  // Re-solved to convergence (within max_solver_iterations), not stopped at the first small
  // step: the solution with the outliers in it can lie far from the one without them (a 1.5 m
  // acoustic outlier pulled a window without lights by 0.4 m, and the solve back from there
  // crawls: 14 iterations). Not restarted from the warm start: when the window itself is wrong
  // and the gate takes out nearly everything (a start from a wrongly identified frame), the pull
  // of the first solve is what brings it back (a Monte-Carlo run diverged without it).
  if (any_gated && !Solve(/*stop_early=*/false)) {
    ++stats_.solver_failures;
    Reset("solver failed at " + std::to_string(frame.t_ns) + " ns (after gating)");
    return std::nullopt;
  }
  if (ResetOnDivergence(static_cast<int>(usbl.size()), usbl_gated, frame.t_ns)) {
    return std::nullopt;
  }
  stats_.gated_observations += state->n_gated;
  stats_.used_observations += static_cast<int>(state->vision.size());
  if (!state->vision.empty()) last_vision_t_ns_ = frame.t_ns;
  while (static_cast<int>(window_.size()) > options_.window_size) MarginalizeOldest();

  // The rate tests of the acoustic measurements bound the vehicle's speed by its estimate.
  const double speed_mps = Eigen::Map<const Eigen::Vector3d>(state->velocity).norm();
  usbl_rate_test_.SetEstimatedSpeed(speed_mps);
  for (UsblRateTest& test : sbl_rate_tests_) test.SetEstimatedSpeed(speed_mps);

  EstimatorOutput out = Output(*state);
  out.n_depth = static_cast<int>(depth.size()) + depth_gated;
  out.n_depth_gated = depth_gated;
  if (out.covariance_ok && options_.adaptive_vision_noise.enabled) {
    UpdateNoiseScales(*state, out.covariance);
  }
  ++stats_.frames_with_output;
  return out;
}

bool SlidingWindowEstimator::ResetOnDivergence(int kept_fixes, int gated_fixes, int64_t t_ns) {
  if (options_.divergence_fixes <= 0 || kept_fixes + gated_fixes == 0) return false;
  for (int k = 0; k < gated_fixes; ++k) recent_fix_gated_.emplace_back(t_ns, true);
  for (int k = 0; k < kept_fixes; ++k) recent_fix_gated_.emplace_back(t_ns, false);
  while (static_cast<int>(recent_fix_gated_.size()) > options_.divergence_fixes) {
    recent_fix_gated_.pop_front();
  }
  if (static_cast<int>(recent_fix_gated_.size()) < options_.divergence_fixes) return false;
  const int refused = static_cast<int>(
      std::count_if(recent_fix_gated_.begin(), recent_fix_gated_.end(),
                    [](const std::pair<int64_t, bool>& verdict) { return verdict.second; }));
  if (refused < options_.divergence_gated_share * options_.divergence_fixes) return false;
  // A light used over the span of these fixes: the lights are believed, not the fixes.
  if (last_vision_t_ns_ != INT64_MIN && last_vision_t_ns_ >= recent_fix_gated_.front().first) {
    return false;
  }
  ++stats_.divergences;
  char text[220];
  std::snprintf(text, sizeof(text),
                "divergence: the gate refused %d of the last %d acoustic fixes, which agree with "
                "each other (rate test), and no light was in use: the state is wrong; restarting "
                "from the fixes at %lld ns",
                refused, options_.divergence_fixes, static_cast<long long>(t_ns));
  recent_fix_gated_.clear();
  Reset(text);
  init_refusal_ = text;  // this frame's reason for no estimate, until the restart
  return true;
}

double SlidingWindowEstimator::WindowVisionFloorPx() const {
  if (!(options_.window_vision_floor_px > 0.0)) return 0.0;  // white errors only
  return std::max(options_.window_vision_floor_px,
                  std::min(options_.max_window_vision_floor_px, slow_vision_error_.slow_px()));
}

double SlidingWindowEstimator::WindowVisionCorrelationTimeS() const {
  const double configured = options_.window_vision_correlation_time_s;
  // The configured time until the residuals show a slow error above the configured floor.
  if (!(slow_vision_error_.slow_px() > options_.window_vision_floor_px)) return configured;
  const double measured = slow_vision_error_.correlation_time_s();
  if (!(measured > 0.0)) return configured;
  return std::clamp(measured, configured,
                    std::max(configured, options_.max_window_vision_correlation_time_s));
}

void SlidingWindowEstimator::UpdateNoiseScales(const State& state, const Matrix6d& covariance) {
  for (const VisionResidual& r : state.vision) {
    const int m = r.mono ? 2 : 3;
    // Problem::EvaluateResidualBlock returns the Jacobian in the pose's tangent space (m x 6,
    // row-major), the space of the covariance.
    Eigen::Vector3d residual = Eigen::Vector3d::Zero();
    Eigen::Matrix<double, 3, kPoseTangentSize, Eigen::RowMajor> J_buffer;
    // The pose is the first block; a time-shifted residual's second, the velocity, is not needed.
    double* jacobians[2] = {J_buffer.data(), nullptr};
    double cost = 0.0;
    if (!problem_->EvaluateResidualBlock(r.id, /*apply_loss_function=*/false, &cost,
                                         residual.data(), jacobians)) {
      continue;
    }
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, kPoseTangentSize, Eigen::RowMajor>>
        J(J_buffer.data(), m, kPoseTangentSize);
    // The residual's share of the fit: its stage weight times J P J^T (J whitened, unweighted).
    const double leverage = r.weight * (J * covariance * J.transpose()).trace();
    auto& scales = r.mono ? mono_noise_ : stereo_noise_;
    auto it = scales.find(r.light_id);
    if (it == scales.end()) {
      it = scales.emplace(r.light_id, AdaptiveNoiseScale(options_.adaptive_vision_noise)).first;
    }
    it->second.Update(residual.head(m).squaredNorm(), std::clamp(m - leverage, 0.0, 1.0 * m));
    (r.mono ? stats_.mono_variance_factor : stats_.stereo_variance_factor)[r.light_id] =
        it->second.factor();
  }
}

std::vector<Rejection> SlidingWindowEstimator::TakeRejections() {
  return std::exchange(rejections_, {});
}

std::optional<Pose3> SlidingWindowEstimator::PropagatedPose(int64_t t_ns) const {
  if (window_.empty()) return std::nullopt;
  const State& newest = *window_.back();
  if (t_ns < newest.t_ns) return std::nullopt;
  if (t_ns == newest.t_ns) return PoseFromBlock(newest.pose);
  const ImuBias bias = BiasFromBlock(newest.bias);
  const std::optional<ImuPreintegration> pim = imu_.Preintegrate(newest.t_ns, t_ns, bias);
  if (!pim) return std::nullopt;
  NavState nav;
  const Pose3 T = PoseFromBlock(newest.pose);
  nav.q_D_B = T.q;
  nav.p_D = T.p;
  nav.v_D = Eigen::Map<const Eigen::Vector3d>(newest.velocity);
  const NavState predicted = pim->Predict(nav, bias, dock_.gravity_D, earth_rate_D_);
  return Pose3(predicted.q_D_B, predicted.p_D);
}

std::vector<StateRecord> SlidingWindowEstimator::History() const {
  std::vector<StateRecord> all = history_;
  for (const auto& state : window_) all.push_back(state->Record());
  return all;
}

}  // namespace auvdock
