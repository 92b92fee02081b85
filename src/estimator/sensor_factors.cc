#include "auvdock/estimator/sensor_factors.h"

#include <cmath>
#include <memory>
#include <utility>

#include <ceres/loss_function.h>

#include "factors/depth_factor.h"
#include "factors/depth_offset_factor.h"
#include "factors/dvl_factor.h"
#include "factors/heading_factor.h"
#include "factors/time_shifted_factor.h"
#include "factors/sbl_range_factor.h"
#include "factors/usbl_fix_factor.h"

namespace auvdock {
namespace {

// A Huber loss at huber_sigmas on the whitened norm; none (plain least squares) at +infinity.
ceres::LossFunction* HuberOrNone(double huber_sigmas) {
  return std::isinf(huber_sigmas) ? nullptr : new ceres::HuberLoss(huber_sigmas);
}

}  // namespace

std::optional<ceres::ResidualBlockId> AddDepthFactor(ceres::Problem* problem,
                                                     const DepthMeasurement& sample,
                                                     const DepthCalibration& calibration,
                                                     const DockModel& dock,
                                                     const StateBlocks& state, int64_t t_state_ns,
                                                     double variance_factor,
                                                     double huber_sigmas) {
  if (!std::isfinite(sample.depth_m) || sample.t_ns < t_state_ns) return std::nullopt;
  const std::optional<ImuPoseShift> shift =
      ImuShiftFromState(state, t_state_ns, sample.t_ns - t_state_ns, dock.gravity_D);
  if (!shift) return std::nullopt;
  const DepthFactor depth(sample.depth_m, calibration.sigma_m * std::sqrt(variance_factor),
                          dock.origin_depth_m, dock.gravity_D, calibration.T_B_S.p);
  if (state.depth_offset != nullptr) {
    if (state.velocity == nullptr) return std::nullopt;
    return problem->AddResidualBlock(DepthOffsetFactor::Create(depth, *shift),
                                     HuberOrNone(huber_sigmas), state.pose, state.velocity,
                                     state.depth_offset);
  }
  return AddOnState<DepthFactor, kDepthResidualSize>(problem, std::make_unique<DepthFactor>(depth),
                                                     *shift, HuberOrNone(huber_sigmas), state);
}

std::optional<ceres::ResidualBlockId> AddHeadingFactor(ceres::Problem* problem,
                                                       const HeadingMeasurement& sample,
                                                       const HeadingCalibration& calibration,
                                                       const DockModel& dock,
                                                       const StateBlocks& state,
                                                       int64_t t_state_ns, double huber_sigmas) {
  if (!std::isfinite(sample.heading_rad) || sample.t_ns < t_state_ns) return std::nullopt;
  const std::optional<ImuPoseShift> shift =
      ImuShiftFromState(state, t_state_ns, sample.t_ns - t_state_ns, dock.gravity_D);
  if (!shift) return std::nullopt;
  return AddOnState<HeadingFactor, kHeadingResidualSize>(
      problem,
      std::make_unique<HeadingFactor>(sample.heading_rad, calibration.sigma_rad,
                                      calibration.T_B_S.q, HeadingReference::OfDock(dock)),
      *shift, HuberOrNone(huber_sigmas), state);
}

std::optional<ceres::ResidualBlockId> AddDvlFactor(ceres::Problem* problem,
                                                   const DvlMeasurement& sample,
                                                   const DvlCalibration& calibration,
                                                   const DockModel& dock,
                                                   const StateBlocks& state, int64_t t_state_ns,
                                                   const ImuPoseShift* shift,
                                                   double variance_factor, double huber_sigmas) {
  if (!sample.v_S.allFinite() || sample.t_ns < t_state_ns || state.imu == nullptr ||
      state.velocity == nullptr) {
    return std::nullopt;
  }
  const std::optional<Eigen::Vector3d> gyro = state.imu->GyroAt(sample.t_ns);
  if (!gyro) return std::nullopt;
  const std::optional<ImuPoseShift> own_shift =
      shift ? std::optional<ImuPoseShift>(*shift)
            : ImuShiftFromState(state, t_state_ns, sample.t_ns - t_state_ns, dock.gravity_D);
  if (!own_shift) return std::nullopt;
  const double sigma_mps = calibration.sigma_mps * std::sqrt(variance_factor);
  if (state.dvl_bias != nullptr) {
    return problem->AddResidualBlock(
        DvlFactor::CreateWithBias(sample.v_S, sigma_mps, calibration.T_B_S, *gyro - state.bias.gyro,
                                  *own_shift),
        HuberOrNone(huber_sigmas), state.pose, state.velocity, state.dvl_bias);
  }
  return problem->AddResidualBlock(DvlFactor::Create(sample.v_S, sigma_mps, calibration.T_B_S,
                                                     *gyro - state.bias.gyro, *own_shift),
                                   HuberOrNone(huber_sigmas), state.pose, state.velocity);
}

std::optional<ceres::ResidualBlockId> AddUsblFactor(ceres::Problem* problem,
                                                    const AcousticFix& fix,
                                                    const AcousticCalibration& calibration,
                                                    const DockModel& dock,
                                                    const StateBlocks& state, int64_t t_state_ns,
                                                    double huber_sigmas) {
  // A fix from before the state (it arrived late) is shifted backward through the IMU.
  if (!fix.p_D.allFinite() || !std::isfinite(fix.sigma_m) || !(fix.sigma_m > 0.0)) {
    return std::nullopt;
  }
  const std::optional<ImuPoseShift> shift =
      ImuShiftFromState(state, t_state_ns, fix.t_ns - t_state_ns, dock.gravity_D);
  if (!shift) return std::nullopt;
  return AddOnState<UsblFixFactor, kUsblResidualSize>(
      problem, std::make_unique<UsblFixFactor>(fix.p_D, fix.sigma_m, calibration.T_B_S.p), *shift,
      HuberOrNone(huber_sigmas), state);
}

std::optional<ceres::ResidualBlockId> AddSblFactor(ceres::Problem* problem,
                                                   const SblRange& range,
                                                   const SblCalibration& calibration,
                                                   const DockModel& dock,
                                                   const StateBlocks& state, int64_t t_state_ns,
                                                   double variance_factor, double huber_sigmas) {
  if (range.transducer < 0 ||
      range.transducer >= static_cast<int>(calibration.p_B_transducers.size()) ||
      !std::isfinite(range.range_m) || range.range_m < 0.0 || !std::isfinite(range.sigma_m) ||
      !(range.sigma_m > 0.0) || range.t_ns < t_state_ns) {
    return std::nullopt;
  }
  const std::optional<ImuPoseShift> shift =
      ImuShiftFromState(state, t_state_ns, range.t_ns - t_state_ns, dock.gravity_D);
  if (!shift) return std::nullopt;
  return AddOnState<SblRangeFactor, kSblRangeResidualSize>(
      problem,
      std::make_unique<SblRangeFactor>(range.range_m, range.sigma_m * std::sqrt(variance_factor),
                                       calibration.p_B_transducers[range.transducer],
                                       dock.p_D_beacon),
      *shift, HuberOrNone(huber_sigmas), state);
}

std::string ImplausibleDepth(const DepthMeasurement& sample) {
  if (!std::isfinite(sample.depth_m)) return "not finite";
  if (sample.depth_m < -0.5) return "above the surface by more than 0.5 m";
  return "";
}

int GateSensorResiduals(ceres::Problem* problem, double gate_chi2, const std::string& sensor,
                        std::vector<SensorResidual>* residuals,
                        std::vector<Rejection>* rejections) {
  int gated = 0;
  std::vector<SensorResidual> kept;
  for (const SensorResidual& residual : *residuals) {
    double cost = 0.0;
    problem->EvaluateResidualBlock(residual.id, /*apply_loss_function=*/false, &cost, nullptr,
                                   nullptr);
    if (gate_chi2 > 0.0 && 2.0 * cost > gate_chi2) {
      problem->RemoveResidualBlock(residual.id);
      ++gated;
      if (rejections) {
        rejections->push_back({residual.t_ns, sensor, 2.0 * cost, "beyond the chi-square gate"});
      }
    } else {
      kept.push_back(residual);
    }
  }
  *residuals = std::move(kept);
  return gated;
}

}  // namespace auvdock
