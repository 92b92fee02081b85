#include "auvdock/estimator/state_blocks.h"

namespace auvdock {

std::optional<ImuPoseShift> ImuShiftFromState(const StateBlocks& state, int64_t t_state_ns,
                                              int64_t dt_ns, const Eigen::Vector3d& gravity_D) {
  ImuPoseShift shift;
  shift.gravity_D = gravity_D;
  if (dt_ns == 0) return shift;
  if (state.imu == nullptr || state.velocity == nullptr) return std::nullopt;
  // Forward over [t_k, t_k + dt], or over [t_k + dt, t_k] for a measurement before the state.
  const int64_t from_ns = dt_ns > 0 ? t_state_ns : t_state_ns + dt_ns;
  const int64_t to_ns = dt_ns > 0 ? t_state_ns + dt_ns : t_state_ns;
  const std::optional<ImuPreintegration> pim = state.imu->Preintegrate(from_ns, to_ns, state.bias);
  if (!pim) return std::nullopt;
  shift.dt_s = dt_ns > 0 ? pim->sum_dt() : -pim->sum_dt();
  shift.delta_q = pim->delta_q();
  shift.delta_p = pim->delta_p();
  shift.delta_v = pim->delta_v();
  return shift;
}

}  // namespace auvdock
