#include "auvdock/sim/docking_trajectory.h"

#include <cmath>

#include "auvdock/sim/smooth_scalar.h"

namespace auvdock {

namespace {

constexpr double kDegToRad = M_PI / 180.0;

Smooth Oscillation(const OscillationConfig& c, double t, double scale) {
  const Smooth phase = (2.0 * M_PI / c.period_s) * Smooth::Time(t) + c.phase_rad;
  return (c.amplitude * scale) * sin(phase);
}

}  // namespace

DockingTrajectory::DockingTrajectory(const DockingTrajectoryConfig& config) : config_(config) {}

KinematicState DockingTrajectory::At(double t) const {
  const auto& c = config_;
  const double T_app = c.approach_end_s;
  const double T_desc = c.touchdown_s - c.descent_start_s;

  // Perturbations fade out over the final descent: envelope 1 -> 0.
  const Smooth envelope = 1.0 + (-1.0) * SmoothStep(t, c.descent_start_s, T_desc);

  // Horizontal approach with an initial speed towards the hover point.
  const Eigen::Vector2d to_hover = (c.hover_p_D - c.start_p_D).head<2>();
  const Eigen::Vector2d v0 =
      to_hover.norm() > 1e-9 ? Eigen::Vector2d(c.start_speed_mps * to_hover.normalized())
                             : Eigen::Vector2d::Zero();
  const Smooth x = QuinticBlend(t, 0.0, T_app, c.start_p_D.x(), v0.x(), c.hover_p_D.x());
  const Smooth y = QuinticBlend(t, 0.0, T_app, c.start_p_D.y(), v0.y(), c.hover_p_D.y()) +
                   envelope * Oscillation(c.current_drift_m, t, 1.0);
  const Smooth z = QuinticBlend(t, 0.0, T_app, c.start_p_D.z(), 0.0, c.hover_p_D.z()) +
                   (c.landed_z_D - c.hover_p_D.z()) * SmoothStep(t, c.descent_start_s, T_desc) +
                   envelope * Oscillation(c.heave_m, t, 1.0);

  const Smooth roll = envelope * Oscillation(c.roll_deg, t, kDegToRad);
  const Smooth pitch = envelope * Oscillation(c.pitch_deg, t, kDegToRad);
  const Smooth yaw = QuinticBlend(t, 0.0, T_app, c.start_yaw_deg * kDegToRad, 0.0, 0.0) +
                     envelope * Oscillation(c.yaw_deg, t, kDegToRad);

  KinematicState s;
  s.T_D_B.p = Eigen::Vector3d(x.v, y.v, z.v);
  s.v_D = Eigen::Vector3d(x.d, y.d, z.d);
  s.a_D = Eigen::Vector3d(x.dd, y.dd, z.dd);
  s.T_D_B.q = Eigen::Quaterniond(Eigen::AngleAxisd(yaw.v, Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(pitch.v, Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(roll.v, Eigen::Vector3d::UnitX()));
  const double sr = std::sin(roll.v), cr = std::cos(roll.v);
  const double sp = std::sin(pitch.v), cp = std::cos(pitch.v);
  s.omega_B = Eigen::Vector3d(roll.d - yaw.d * sp, pitch.d * cr + yaw.d * cp * sr,
                              -pitch.d * sr + yaw.d * cp * cr);
  return s;
}

}  // namespace auvdock
