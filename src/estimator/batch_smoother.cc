#include "auvdock/estimator/batch_smoother.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>

#include <ceres/covariance.h>
#include <ceres/iteration_callback.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include "auvdock/estimator/chain_marginals.h"
#include "auvdock/estimator/chain_solver.h"
#include "auvdock/estimator/imu_buffer.h"
#include "auvdock/estimator/sensor_factors.h"
#include "auvdock/estimator/vision_factors.h"
#include "factors/bias_prior_factor.h"
#include "factors/depth_offset_factor.h"
#include "factors/dvl_factor.h"
#include "factors/imu_preintegration_factor.h"
#include "factors/pose_manifold.h"
#include "factors/pose_prior_factor.h"
#include "factors/scalar_random_walk_factor.h"
#include "factors/vector_random_walk_factor.h"
#include "factors/velocity_prior_factor.h"

namespace auvdock {
namespace {

struct BatchState {
  int64_t t_ns = 0;
  double pose[kPoseSize];
  double velocity[kVelocitySize];
  double bias[kBiasSize];
  double depth_offset[kDepthOffsetSize] = {0.0};  // m; a block only with estimate_depth_offset
  double dvl_bias[kDvlBiasSize] = {0.0, 0.0, 0.0};  // m/s in S; a block only with estimate_dvl_bias
  std::vector<VisionResidual> vision;
  int n_gated = 0;
};

class ProgressCallback final : public ceres::IterationCallback {
 public:
  explicit ProgressCallback(const std::function<void(int, double)>& progress)
      : progress_(progress) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (progress_) progress_(summary.iteration, summary.cost);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const std::function<void(int, double)>& progress_;
};

// Which of the optional blocks every state carries.
struct OptionalBlocks {
  bool depth_offset = false;  // EstimatesDepthOffset
  bool dvl_bias = false;      // EstimatesDvlBias
};

// Each state's blocks (pose, velocity, bias, the DVL's bias and the depth offset when they are
// estimated, the depth offset last), in time order: the chain of chain_solver.h and
// chain_marginals.h.
std::vector<std::vector<double*>> ChainBlocks(
    const std::vector<std::unique_ptr<BatchState>>& states, const OptionalBlocks& with) {
  std::vector<std::vector<double*>> chain;
  chain.reserve(states.size());
  for (const auto& s : states) {
    chain.push_back({s->pose, s->velocity, s->bias});
    if (with.dvl_bias) chain.back().push_back(s->dvl_bias);
    if (with.depth_offset) chain.back().push_back(s->depth_offset);
  }
  return chain;
}

// What the batch reports of a solve.
struct BatchSolve {
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;  // counting the evaluation at the start, as Ceres does
  bool converged = false;
};

// The batch is a chain (IMU factors between neighbours, every other factor on one state): the
// chain solver (chain_solver.h) at Ceres' tolerances and damping takes Ceres' steps without its
// general sparse Cholesky; Ceres solves anything else, or everything with chain_solver off.
BatchSolve SolveBatch(ceres::Problem* problem,
                      const std::vector<std::unique_ptr<BatchState>>& states,
                      const OptionalBlocks& with, const ceres::Solver::Options& solver,
                      const EstimatorOptions& o, const std::function<void(int, double)>& progress) {
  BatchSolve result;
  if (o.chain_solver) {
    ChainSolverOptions chain;
    chain.max_iterations = solver.max_num_iterations;
    chain.function_tolerance = solver.function_tolerance;
    chain.gradient_tolerance = solver.gradient_tolerance;
    chain.parameter_tolerance = solver.parameter_tolerance;
    chain.initial_lambda = o.solver_initial_damping;
    chain.progress = progress;
    if (const std::optional<ChainSolverSummary> summary =
            SolveChain(problem, ChainBlocks(states, with), chain)) {
      result.initial_cost = summary->initial_cost;
      result.final_cost = summary->final_cost;
      result.iterations = summary->iterations + 1;
      result.converged = summary->converged;
      return result;
    }
  }
  ceres::Solver::Options options = solver;
  ProgressCallback callback(progress);
  options.callbacks.push_back(&callback);
  ceres::Solver::Summary summary;
  ceres::Solve(options, problem, &summary);
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.iterations = static_cast<int>(summary.iterations.size());
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  return result;
}

// The priors of a segment's first state: the given start's pose and velocity with their
// covariance when the user gave one for this state, else the initial sigmas about the warm start
// (pose) and zero (velocity); the biases' always.
void AddInitialPriors(ceres::Problem* problem, const EstimatorOptions& o, BatchState* s,
                      const InitialState* given_start) {
  if (given_start != nullptr) {
    problem->AddResidualBlock(
        PosePriorFactor::Create(given_start->T_D_B, given_start->pose_covariance), nullptr,
        s->pose);
    problem->AddResidualBlock(
        VelocityPriorFactor::Create(given_start->v_D, given_start->velocity_covariance), nullptr,
        s->velocity);
  } else {
    Matrix6d pose_cov = Matrix6d::Zero();
    pose_cov.topLeftCorner<3, 3>().diagonal().setConstant(o.init_position_sigma_m *
                                                          o.init_position_sigma_m);
    pose_cov.bottomRightCorner<3, 3>().diagonal().setConstant(o.init_attitude_sigma_rad *
                                                              o.init_attitude_sigma_rad);
    problem->AddResidualBlock(PosePriorFactor::Create(PoseFromBlock(s->pose), pose_cov), nullptr,
                              s->pose);
    problem->AddResidualBlock(
        VelocityPriorFactor::Create(
            Eigen::Vector3d::Zero(),
            Eigen::Matrix3d::Identity() * o.init_velocity_sigma_mps * o.init_velocity_sigma_mps),
        nullptr, s->velocity);
  }
  Matrix6d bias_cov = Matrix6d::Zero();
  bias_cov.topLeftCorner<3, 3>().diagonal().setConstant(o.init_gyro_bias_sigma *
                                                        o.init_gyro_bias_sigma);
  bias_cov.bottomRightCorner<3, 3>().diagonal().setConstant(o.init_accel_bias_sigma *
                                                            o.init_accel_bias_sigma);
  problem->AddResidualBlock(BiasPriorFactor::Create(Eigen::Matrix<double, 6, 1>::Zero(), bias_cov),
                            nullptr, s->bias);
}

// Median interval between consecutive states (s); 0 with fewer than two states.
double MedianStateInterval(const std::vector<std::unique_ptr<BatchState>>& states) {
  std::vector<double> intervals;
  for (size_t k = 1; k < states.size(); ++k) {
    intervals.push_back(1e-9 * static_cast<double>(states[k]->t_ns - states[k - 1]->t_ns));
  }
  if (intervals.empty()) return 0.0;
  std::nth_element(intervals.begin(), intervals.begin() + intervals.size() / 2, intervals.end());
  return intervals[intervals.size() / 2];
}

// Marginal covariance of every pose (tangent space, 6x6; nullopt where it could not be had):
// by the chain's two sweeps (chain_marginals.h, linear in the number of states); by
// ceres::Covariance when the problem is not a chain, or when the sweeps find a segment
// rank-deficient: they work on H = J^T J, whose condition number is the square of J's, and a
// long stretch on the IMU alone can leave a legitimately small information at rounding level
// there; the QR of J decides. With the depth offset, *offset_variances gets each state's offset
// variance (the offset block is a state's last coordinate; NaN where not had).
std::vector<std::optional<Eigen::Matrix<double, 6, 6>>> PoseMarginals(
    ceres::Problem* problem, const std::vector<std::unique_ptr<BatchState>>& states,
    const OptionalBlocks& with, std::vector<double>* offset_variances) {
  std::vector<std::optional<Eigen::Matrix<double, 6, 6>>> marginals(states.size());
  offset_variances->assign(states.size(), std::numeric_limits<double>::quiet_NaN());
  const std::optional<std::vector<std::optional<Eigen::MatrixXd>>> chain_marginals =
      ChainMarginals(problem, ChainBlocks(states, with));
  if (chain_marginals &&
      std::all_of(chain_marginals->begin(), chain_marginals->end(),
                  [](const std::optional<Eigen::MatrixXd>& m) { return m.has_value(); })) {
    for (size_t k = 0; k < states.size(); ++k) {
      const Eigen::MatrixXd& full = *(*chain_marginals)[k];
      const Eigen::Matrix<double, 6, 6> pose = full.topLeftCorner<6, 6>();
      if (pose.allFinite()) marginals[k] = pose;
      if (with.depth_offset) (*offset_variances)[k] = full(full.rows() - 1, full.cols() - 1);
    }
    return marginals;
  }
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::SPARSE_QR;
  options.num_threads = 1;
  ceres::Covariance covariance(options);
  std::vector<std::pair<const double*, const double*>> blocks;
  for (const auto& s : states) blocks.emplace_back(s->pose, s->pose);
  if (!covariance.Compute(blocks, problem)) return marginals;
  for (size_t k = 0; k < states.size(); ++k) {
    Eigen::Matrix<double, 6, 6, Eigen::RowMajor> pose;
    if (covariance.GetCovarianceMatrixInTangentSpace({states[k]->pose}, pose.data()) &&
        pose.allFinite()) {
      marginals[k] = pose;
    }
  }
  return marginals;
}

}  // namespace


BatchResult SmoothBatch(const Calibration& calibration, const DockModel& dock,
                        const std::vector<VisionFrame>& frames,
                        const std::vector<ImuSample>& imu,
                        const std::vector<StateRecord>& warm_start,
                        const EstimatorOptions& estimator_options,
                        const BatchSmootherOptions& options,
                        const NavigationSamples& sensors) {
  if (!calibration.imu) throw std::invalid_argument("SmoothBatch: the calibration has no IMU");
  BatchResult result;
  ImuBuffer buffer(*calibration.imu, estimator_options.max_imu_gap_s,
                   estimator_options.imu_noise_scale);
  for (const ImuSample& sample : imu) {
    if (!buffer.Add(sample).empty()) ++result.stats.skipped_imu;
  }
  VisionRig rig;
  rig.stereo_left = calibration.FindCameraByRole(CameraRole::kStereoLeft);
  rig.stereo_right = calibration.FindCameraByRole(CameraRole::kStereoRight);
  rig.mono = calibration.FindCameraByRole(CameraRole::kMono);
  rig.dock = &dock;
  std::map<int64_t, const VisionFrame*> frame_at;
  for (const VisionFrame& f : frames) frame_at[f.t_ns] = &f;

  // States from the warm start, strictly increasing in time.
  std::vector<std::unique_ptr<BatchState>> states;
  for (const StateRecord& r : warm_start) {
    if (!states.empty() && r.t_ns <= states.back()->t_ns) continue;
    auto s = std::make_unique<BatchState>();
    s->t_ns = r.t_ns;
    std::copy(r.pose, r.pose + kPoseSize, s->pose);
    std::copy(r.velocity, r.velocity + kVelocitySize, s->velocity);
    std::copy(r.bias, r.bias + kBiasSize, s->bias);
    s->depth_offset[0] = r.depth_offset;
    std::copy(r.dvl_bias, r.dvl_bias + kDvlBiasSize, s->dvl_bias);
    states.push_back(std::move(s));
  }

  VisionFactorOptions vision_options = estimator_options.vision;
  vision_options.correlated_pixel_variance = CorrelatedVisionVariance(
      estimator_options.smoother_vision_floor_px,
      estimator_options.smoother_vision_correlation_time_s, MedianStateInterval(states));
  if (options.information_at_warm_start) {
    vision_options.huber_sigmas = std::numeric_limits<double>::infinity();
  }

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.enable_fast_removal = true;
  ceres::Problem problem(problem_options);
  const PoseManifold manifold;
  const OptionalBlocks with{EstimatesDepthOffset(estimator_options, calibration),
                            EstimatesDvlBias(estimator_options, calibration)};
  for (size_t k = 0; k < states.size(); ++k) {
    BatchState* s = states[k].get();
    problem.AddParameterBlock(s->pose, kPoseSize, const_cast<PoseManifold*>(&manifold));
    problem.AddParameterBlock(s->velocity, kVelocitySize);
    problem.AddParameterBlock(s->bias, kBiasSize);
    if (with.dvl_bias) {
      // The DVL's bias along the whole log, drifting as a random walk; its prior at the start.
      problem.AddParameterBlock(s->dvl_bias, kDvlBiasSize);
      if (k == 0) {
        problem.AddResidualBlock(
            VectorPriorFactor::Create(Eigen::Vector3d::Zero(),
                                      estimator_options.dvl_bias_prior_sigma_mps),
            nullptr, s->dvl_bias);
      } else {
        problem.AddResidualBlock(VectorRandomWalkFactor::Create(
                                     estimator_options.dvl_bias_random_walk,
                                     1e-9 * static_cast<double>(s->t_ns - states[k - 1]->t_ns)),
                                 nullptr, states[k - 1]->dvl_bias, s->dvl_bias);
      }
    }
    if (with.depth_offset) {
      // One offset along the whole log, drifting as a random walk; its prior at the start.
      problem.AddParameterBlock(s->depth_offset, kDepthOffsetSize);
      if (k == 0) {
        problem.AddResidualBlock(
            ScalarPriorFactor::Create(0.0, estimator_options.depth_offset_prior_sigma_m), nullptr,
            s->depth_offset);
      } else {
        problem.AddResidualBlock(
            ScalarRandomWalkFactor::Create(estimator_options.depth_offset_random_walk,
                                           1e-9 * static_cast<double>(s->t_ns - states[k - 1]->t_ns)),
            nullptr, states[k - 1]->depth_offset, s->depth_offset);
      }
    }
    bool joined = false;
    if (k > 0) {
      BatchState* p = states[k - 1].get();
      const ImuBias bias = BiasFromBlock(p->bias);
      const std::optional<ImuPreintegration> pim = buffer.Preintegrate(p->t_ns, s->t_ns, bias);
      if (pim) {
        problem.AddResidualBlock(
            ImuPreintegrationFactor::Create(*pim, dock.gravity_D, EarthRate_D(dock)), nullptr,
            p->pose, p->velocity, p->bias, s->pose, s->velocity, s->bias);
        joined = true;
      }
    }
    if (!joined) {
      const bool given = options.start && options.start->t_ns == s->t_ns;
      AddInitialPriors(&problem, estimator_options, s, given ? &*options.start : nullptr);
      ++result.segments;
    }
    const auto f = frame_at.find(s->t_ns);
    if (f != frame_at.end()) {
      const ImuBias bias = BiasFromBlock(s->bias);
      s->vision = AddVisionFactors(&problem, *f->second, rig, vision_options,
                                   StateBlocks(s->pose, s->velocity, &buffer, bias),
                                   &result.stats.skipped_observations);
    }
  }
  if (states.empty()) return result;
  // Depth and DVL samples on the states at or before them.
  const auto state_at_or_before = [&](int64_t t_ns) -> BatchState* {
    const auto after = std::upper_bound(
        states.begin(), states.end(), t_ns,
        [](int64_t t, const std::unique_ptr<BatchState>& s) { return t < s->t_ns; });
    return after == states.begin() ? nullptr : std::prev(after)->get();
  };
  const auto blocks_of = [&](BatchState* s) {
    return StateBlocks(s->pose, s->velocity, &buffer, BiasFromBlock(s->bias),
                       with.depth_offset ? s->depth_offset : nullptr,
                       with.dvl_bias ? s->dvl_bias : nullptr);
  };
  std::vector<SensorResidual> depth_residuals;
  if (estimator_options.use_depth && calibration.depth) {
    for (const DepthMeasurement& sample : sensors.depth) {
      if (const std::string problem = ImplausibleDepth(sample); !problem.empty()) {
        ++result.stats.depth_skipped;
        result.rejections.push_back({sample.t_ns, calibration.depth->name, kNoStatistic, problem});
        continue;
      }
      std::optional<ceres::ResidualBlockId> id;
      if (BatchState* s = state_at_or_before(sample.t_ns)) {
        id = AddDepthFactor(&problem, sample, *calibration.depth, dock, blocks_of(s), s->t_ns,
                            sensors.depth_variance_factor);
      }
      if (id) {
        depth_residuals.push_back({*id, sample.t_ns});
      } else {
        ++result.stats.depth_skipped;
        result.rejections.push_back({sample.t_ns, calibration.depth->name, kNoStatistic, kNoStateReason});
      }
    }
  }
  std::vector<SensorResidual> heading_residuals;
  if (estimator_options.use_heading && calibration.heading) {
    for (const HeadingMeasurement& sample : sensors.heading) {
      std::optional<ceres::ResidualBlockId> id;
      if (BatchState* s = state_at_or_before(sample.t_ns)) {
        id = AddHeadingFactor(&problem, sample, *calibration.heading, dock, blocks_of(s), s->t_ns);
      }
      if (id) {
        heading_residuals.push_back({*id, sample.t_ns});
      } else {
        ++result.stats.heading_skipped;
        result.rejections.push_back({sample.t_ns, calibration.heading->name, kNoStatistic,
                                     std::isfinite(sample.heading_rad) ? kNoStateReason
                                                                       : "not finite"});
      }
    }
  }
  std::vector<SensorResidual> dvl_residuals;
  if (estimator_options.use_dvl && calibration.dvl) {
    HeldDvlReadingCheck held;
    for (const DvlMeasurement& sample : sensors.dvl) {
      if (!sample.v_S.allFinite()) {
        ++result.stats.dvl_no_lock;
        continue;
      }
      if (const std::string problem = held.Check(sample); !problem.empty()) {
        ++result.stats.dvl_skipped;
        result.rejections.push_back({sample.t_ns, calibration.dvl->name, kNoStatistic, problem});
        continue;
      }
      std::optional<ceres::ResidualBlockId> id;
      if (BatchState* s = state_at_or_before(sample.t_ns)) {
        id = AddDvlFactor(&problem, sample, *calibration.dvl, dock, blocks_of(s), s->t_ns,
                          nullptr, sensors.dvl_variance_factor);
      }
      if (id) {
        dvl_residuals.push_back({*id, sample.t_ns});
      } else {
        ++result.stats.dvl_skipped;
        result.rejections.push_back({sample.t_ns, calibration.dvl->name, kNoStatistic, kNoStateReason});
      }
    }
  }
  std::vector<SensorResidual> usbl_residuals;
  if (estimator_options.use_usbl && calibration.acoustic) {
    int64_t last_t_ns = INT64_MIN;
    for (const AcousticFix& fix : sensors.usbl) {
      std::optional<ceres::ResidualBlockId> id;
      BatchState* s = fix.t_ns > last_t_ns ? state_at_or_before(fix.t_ns) : nullptr;
      if (s) id = AddUsblFactor(&problem, fix, *calibration.acoustic, dock, blocks_of(s), s->t_ns);
      if (id) {
        usbl_residuals.push_back({*id, fix.t_ns});
        last_t_ns = fix.t_ns;
      } else {
        ++result.stats.usbl_skipped;
        result.rejections.push_back({fix.t_ns, calibration.acoustic->name, kNoStatistic,
                                     fix.t_ns <= last_t_ns ? "out of order or repeated"
                                                           : kNoStateReason});
      }
    }
  }
  std::vector<SensorResidual> sbl_residuals;
  if (estimator_options.use_sbl && calibration.sbl) {
    int64_t last_t_ns = INT64_MIN;
    int last_transducer = -1;
    for (const SblRange& range : sensors.sbl) {
      const bool in_order = range.t_ns > last_t_ns ||
                            (range.t_ns == last_t_ns && range.transducer > last_transducer);
      std::optional<ceres::ResidualBlockId> id;
      BatchState* s = in_order ? state_at_or_before(range.t_ns) : nullptr;
      if (s) {
        id = AddSblFactor(&problem, range, *calibration.sbl, dock, blocks_of(s), s->t_ns,
                          sensors.sbl_variance_factor);
      }
      if (id) {
        sbl_residuals.push_back({*id, range.t_ns});
        last_t_ns = range.t_ns;
        last_transducer = range.transducer;
      } else {
        ++result.stats.sbl_skipped;
        result.rejections.push_back({range.t_ns, calibration.sbl->name, kNoStatistic,
                                     !in_order ? "out of order or repeated"
                                     : s       ? "not finite or unknown transducer"
                                               : kNoStateReason});
      }
    }
  }

  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  // No iteration: Solve only evaluates the cost at the warm start.
  solver.max_num_iterations = options.information_at_warm_start ? 0 : options.max_iterations;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  // The navigation sensors are gated twice: at the warm start (the window's estimate, good
  // enough to tell a DVL spike of 0.3 m/s from 1 cm/s noise) before the solve, so that spikes
  // without a robust loss do not pull the whole batch and drag clean samples past the gate with
  // them, and again after it.
  // One sensor's residuals through its gate (sensor: its calibration, present whenever it has
  // residuals).
  const auto gate = [&](std::vector<SensorResidual>* residuals, double gate_chi2,
                        const auto& sensor) {
    return residuals->empty() ? 0
                              : GateSensorResiduals(&problem, gate_chi2, sensor->name, residuals,
                                                    &result.rejections);
  };
  const auto gate_depth = [&] {
    return gate(&depth_residuals, estimator_options.depth_gate_chi2, calibration.depth);
  };
  const auto gate_dvl = [&] {
    return gate(&dvl_residuals, estimator_options.dvl_gate_chi2, calibration.dvl);
  };
  const auto gate_usbl = [&] {
    return gate(&usbl_residuals, estimator_options.usbl_gate_chi2, calibration.acoustic);
  };
  const auto gate_heading = [&] {
    return gate(&heading_residuals, estimator_options.heading_gate_chi2, calibration.heading);
  };
  result.stats.heading_gated = gate_heading();
  result.stats.depth_gated = gate_depth();
  result.stats.dvl_gated = gate_dvl();
  result.stats.usbl_gated = gate_usbl();
  const auto gate_sbl = [&] {
    return gate(&sbl_residuals, estimator_options.sbl_gate_chi2, calibration.sbl);
  };
  result.stats.sbl_gated = gate_sbl();
  BatchSolve summary =
      SolveBatch(&problem, states, with, solver, estimator_options, options.progress);
  result.initial_cost = summary.initial_cost;
  int gated = 0;
  for (auto& s : states) {
    s->n_gated = GateVisionResiduals(&problem, estimator_options.mono_gate_chi2,
                                     estimator_options.stereo_gate_chi2, &s->vision,
                                     &result.rejections);
    gated += s->n_gated;
  }
  const int depth_gated_after = gate_depth();
  result.stats.depth_gated += depth_gated_after;
  result.stats.depth_used = static_cast<int>(depth_residuals.size());
  const int dvl_gated_after = gate_dvl();
  result.stats.dvl_gated += dvl_gated_after;
  result.stats.dvl_used = static_cast<int>(dvl_residuals.size());
  const int usbl_gated_after = gate_usbl();
  result.stats.usbl_gated += usbl_gated_after;
  result.stats.usbl_used = static_cast<int>(usbl_residuals.size());
  const int heading_gated_after = gate_heading();
  result.stats.heading_gated += heading_gated_after;
  result.stats.heading_used = static_cast<int>(heading_residuals.size());
  const int sbl_gated_after = gate_sbl();
  result.stats.sbl_gated += sbl_gated_after;
  result.stats.sbl_used = static_cast<int>(sbl_residuals.size());
  if (gated > 0 || depth_gated_after > 0 || dvl_gated_after > 0 || usbl_gated_after > 0 ||
      sbl_gated_after > 0 || heading_gated_after > 0) {
    summary = SolveBatch(&problem, states, with, solver, estimator_options, options.progress);
  }
  std::stable_sort(result.rejections.begin(), result.rejections.end(),
                   [](const Rejection& a, const Rejection& b) { return a.t_ns < b.t_ns; });
  {
    std::vector<VisionResidual> all_vision;
    for (const auto& s : states) all_vision.insert(all_vision.end(), s->vision.begin(), s->vision.end());
    const double interval_s = MedianStateInterval(states);
    result.vision_errors = MeasureVisionErrors(
        problem, all_vision, static_cast<int64_t>(1.5e9 * interval_s));
  }
  result.final_cost = summary.final_cost;
  result.iterations = summary.iterations;
  result.converged = summary.converged;

  std::vector<double> offset_variances;
  const std::vector<std::optional<Eigen::Matrix<double, 6, 6>>> pose_covariances =
      PoseMarginals(&problem, states, with, &offset_variances);
  int64_t last_vision = INT64_MIN;
  std::vector<int64_t> dvl_times;  // of the DVL samples kept, for the go/no-go's DVL age
  for (const SensorResidual& r : dvl_residuals) dvl_times.push_back(r.t_ns);
  std::sort(dvl_times.begin(), dvl_times.end());
  for (size_t k = 0; k < states.size(); ++k) {
    const auto& s = states[k];
    EstimatorOutput out;
    out.t_ns = s->t_ns;
    out.T_D_B = PoseFromBlock(s->pose);
    out.v_D = Eigen::Map<const Eigen::Vector3d>(s->velocity);
    out.bias = BiasFromBlock(s->bias);
    if (with.depth_offset) {
      out.depth_offset_m = s->depth_offset[0];
      if (offset_variances[k] >= 0.0) out.depth_offset_sigma_m = std::sqrt(offset_variances[k]);
    }
    for (const VisionResidual& r : s->vision) (r.mono ? out.n_mono : out.n_stereo) += 1;
    out.n_gated = s->n_gated;
    if (!s->vision.empty()) last_vision = s->t_ns;
    out.seconds_since_vision =
        last_vision == INT64_MIN ? -1.0 : 1e-9 * static_cast<double>(s->t_ns - last_vision);
    const auto dvl_after = std::upper_bound(dvl_times.begin(), dvl_times.end(), s->t_ns);
    out.seconds_since_dvl =
        dvl_after == dvl_times.begin()
            ? -1.0
            : 1e-9 * static_cast<double>(s->t_ns - *std::prev(dvl_after));
    if (pose_covariances[k]) {
      out.covariance = *pose_covariances[k];
      out.covariance_ok = true;
    }
    if (!out.covariance_ok) ++result.stats.covariance_failures;
    const bool finite = out.T_D_B.p.allFinite() && out.T_D_B.q.coeffs().allFinite();
    if (!finite) continue;  // never report a NaN pose
    result.stats.used_observations += static_cast<int>(s->vision.size());
    result.stats.gated_observations += s->n_gated;
    result.outputs.push_back(out);
  }
  result.stats.frames = static_cast<int>(frames.size());
  result.stats.frames_with_output = static_cast<int>(result.outputs.size());
  return result;
}

}  // namespace auvdock
