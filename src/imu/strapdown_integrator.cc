#include "auvdock/imu/strapdown_integrator.h"

namespace auvdock {

namespace {

struct Derivative {
  Eigen::Vector4d dq;  // quaternion coefficients (x, y, z, w)
  Eigen::Vector3d dp;
  Eigen::Vector3d dv;
};

struct RawState {
  Eigen::Vector4d q;  // x, y, z, w (Eigen's memory order), not necessarily unit mid-step
  Eigen::Vector3d p;
  Eigen::Vector3d v;
};

Derivative Evaluate(const RawState& s, const Eigen::Vector3d& w_B, const Eigen::Vector3d& f_B,
                    const Eigen::Vector3d& g_D) {
  const Eigen::Quaterniond q(s.q(3), s.q(0), s.q(1), s.q(2));
  const Eigen::Quaterniond omega(0.0, w_B.x(), w_B.y(), w_B.z());
  Derivative d;
  d.dq = 0.5 * (q * omega).coeffs();
  d.dp = s.v;
  d.dv = q.normalized() * f_B + g_D;
  return d;
}

RawState Advance(const RawState& s, const Derivative& d, double h) {
  return {s.q + h * d.dq, s.p + h * d.dp, s.v + h * d.dv};
}

}  // namespace

NavState StrapdownIntegrator::Step(const NavState& state, const ImuSample& a,
                                   const ImuSample& b) const {
  const double dt = static_cast<double>(b.t_ns - a.t_ns) * 1e-9;
  const Eigen::Vector3d w_mid = 0.5 * (a.gyro + b.gyro);
  const Eigen::Vector3d f_mid = 0.5 * (a.accel + b.accel);
  const RawState s0{state.q_D_B.coeffs(), state.p_D, state.v_D};
  const Derivative k1 = Evaluate(s0, a.gyro, a.accel, gravity_D_);
  const Derivative k2 = Evaluate(Advance(s0, k1, 0.5 * dt), w_mid, f_mid, gravity_D_);
  const Derivative k3 = Evaluate(Advance(s0, k2, 0.5 * dt), w_mid, f_mid, gravity_D_);
  const Derivative k4 = Evaluate(Advance(s0, k3, dt), b.gyro, b.accel, gravity_D_);
  const double h6 = dt / 6.0;
  NavState out;
  const Eigen::Vector4d q = s0.q + h6 * (k1.dq + 2.0 * k2.dq + 2.0 * k3.dq + k4.dq);
  out.q_D_B = Eigen::Quaterniond(q(3), q(0), q(1), q(2)).normalized();
  out.p_D = s0.p + h6 * (k1.dp + 2.0 * k2.dp + 2.0 * k3.dp + k4.dp);
  out.v_D = s0.v + h6 * (k1.dv + 2.0 * k2.dv + 2.0 * k3.dv + k4.dv);
  return out;
}

}  // namespace auvdock
