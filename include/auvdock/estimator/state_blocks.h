// One estimator state's Ceres parameter blocks as the measurement factors see them (vision,
// depth, DVL: estimator/vision_factors.h, estimator/sensor_factors.h), and the IMU's motion from
// the state's time to a measurement's own time.
//
// A measurement at t >= t_k attaches to state k: at t = t_k directly on its blocks, later through
// the IMU preintegrated over [t_k, t] at the state's current bias estimate (ImuPoseShift,
// factors/time_shifted_factor.h), so that no extra state is needed for it. A measurement that
// arrives after its time has left the window (a late acoustic fix) attaches to the oldest state
// through the IMU over [t, t_0], shifted backward.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <utility>

#include <ceres/autodiff_cost_function.h>
#include <ceres/problem.h>
#include <Eigen/Core>

#include "auvdock/estimator/imu_buffer.h"
#include "auvdock/imu/imu_preintegration.h"
#include "factors/analytic_pose_cost_function.h"
#include "factors/time_shifted_factor.h"

namespace auvdock {

// The pose block (factors/pose_manifold.h) and, for measurements after the state's time, its
// velocity block, the IMU and the bias to preintegrate at. velocity and imu may be null for a
// measurement at the state's own time. depth_offset: the state's depth-sensor offset block
// (factors/depth_offset_factor.h) when the estimator estimates one, else null. dvl_bias: the
// state's DVL-bias block (factors/dvl_factor.h) when the estimator estimates one, else null.
struct StateBlocks {
  explicit StateBlocks(double* pose_block, double* velocity_block = nullptr,
                       const ImuBuffer* imu_buffer = nullptr, const ImuBias& state_bias = {},
                       double* depth_offset_block = nullptr, double* dvl_bias_block = nullptr)
      : pose(pose_block),
        velocity(velocity_block),
        imu(imu_buffer),
        bias(state_bias),
        depth_offset(depth_offset_block),
        dvl_bias(dvl_bias_block) {}
  double* pose;
  double* velocity;
  const ImuBuffer* imu;
  ImuBias bias;
  double* depth_offset;
  double* dvl_bias;
};

// The IMU's motion from the state's time t_state_ns to dt_ns later (dt_ns < 0: earlier, a late
// measurement from before the oldest state; factors/time_shifted_factor.h): an identity shift
// for dt_ns == 0, nothing when the state has no velocity block or IMU, or the IMU does not cover
// the interval.
std::optional<ImuPoseShift> ImuShiftFromState(const StateBlocks& state, int64_t t_state_ns,
                                              int64_t dt_ns, const Eigen::Vector3d& gravity_D);

// Adds `factor` (an automatic-differentiation functor on the pose block with kResiduals
// residuals, e.g. factors/depth_factor.h) on the state: directly on its pose when the shift is
// the identity (dt 0), with the factor's analytic Jacobian when it has one (EvaluateTangent,
// factors/analytic_pose_cost_function.h: the vision factors), else through the shift on its pose
// and velocity (TimeShiftedFactor, automatic differentiation).
// loss may be null. The one way every measurement factor joins a state.
template <typename Factor, int kResiduals>
ceres::ResidualBlockId AddOnState(ceres::Problem* problem, std::unique_ptr<Factor> factor,
                                  const ImuPoseShift& shift, ceres::LossFunction* loss,
                                  const StateBlocks& state) {
  if (shift.dt_s == 0.0) {
    ceres::CostFunction* cost = nullptr;
    if constexpr (HasTangentJacobian<Factor>::value) {
      cost = new AnalyticPoseCostFunction<Factor, kResiduals>(std::move(factor));
    } else {
      cost = new ceres::AutoDiffCostFunction<Factor, kResiduals, kPoseSize>(factor.release());
    }
    return problem->AddResidualBlock(cost, loss, state.pose);
  }
  return problem->AddResidualBlock(
      TimeShiftedFactor<Factor, kResiduals>::Create(std::move(factor), shift), loss, state.pose,
      state.velocity);
}

}  // namespace auvdock
