// A first state without vision: from acoustic fixes, DVL velocities and the IMU, far from the
// dock, before any light is seen (the acoustic phase of seeds 001 and 003).
//
// The fixes give the position, the accelerometer the tilt, and the heading comes from the
// motion: the DVL's velocities, rotated by the gyro and integrated, trace the path in a frame
// that differs from D only by a rotation psi about gravity; the fixes trace the same path in D.
//
// Frames: D the dock's (gravity g_D, unit g), B the body (IMU), S the DVL, T the acoustic
// transponder (T_B_S of the calibration's acoustic sensor). W is D turned by -psi about g: the
// frame of the dead reckoning, with R_W_B0 = the tilt (the rotation taking the mean specific
// force f_B over the first half second onto -g, the vehicle assumed unaccelerated) and
//   R_W_B(t)  = R_W_B0 R_B0_B(t)                        (the gyro's rotation, zero bias)
//   v_B(t)    = R_B_S v_S(t) - w_B(t) x p_B_S           (DVL sample, its lever arm)
//   d(t)      = integral of R_W_B v_B dt from t0        (trapezoid between DVL samples)
// Each fix i (measurement time t_i, sigma_i) of the transponder gives the body's position
//   b_i = fix_i - R_D_B(t_i) p_B_T,   and the model   b_i = c + R_g(psi) d(t_i)   (3 dof each).
// With weights w_i = 1 / sigma_i^2, weighted means b_bar, d_bar, horizontal parts (P = I - g g^T)
// a_i = P (d_i - d_bar), e_i = P (b_i - b_bar):
//   psi = atan2(sum w_i g . (a_i x e_i), sum w_i a_i . e_i),    c = b_bar - R_g(psi) d_bar
// (weighted 2-D Procrustes); the lever arm is taken at psi = 0 first, then at the fitted psi.
// A fix whose residual r_i = b_i - c - R_g(psi) d_i has |r_i|^2 / sigma_i^2 above gate_chi2
// (3 dof) is an outlier (multipath): the worst is dropped and the fit repeated. When that leaves
// out more fixes than it keeps (at least 3), the fixes and the path disagree as a whole (a DVL
// turned from its T_B_S, fixes in another frame): no state, with that reason.
//
// The state at t (a frame's time, after the last DVL sample: extrapolated at its velocity):
//   R_D_B = R_g(psi) R_W_B(t),  p_D = b_bar + R_g(psi) (d(t) - d_bar),  v_D = R_D_B v_B(last)
// Covariance in the window's tangent space [dp_D, dtheta_D] (dtheta on the left, in D), from
//   sigma_psi^2 = 1 / sum w_i |a_i|^2 + (gyro_bias_sigma (t - t_bar))^2
//   (the fit's heading; the gyro bias's heading drift since the fits' mean time t_bar),
//   Cov(b_bar) = I / sum w_i,  j = g x R_g(psi) (d(t) - d_bar)  (the position's lever on psi):
//   P_pp = I / sum w_i + sigma_psi^2 j j^T,   P_p,theta = sigma_psi^2 j g^T,
//   P_theta,theta = tilt_sigma^2 P + sigma_psi^2 g g^T,
// all scaled by the fit's a-posteriori variance factor when it exceeds 1 (sum of the kept
// residuals' statistics over their dof, 3 n - 4). The velocity's covariance is
// velocity_sigma^2 I + (|v| sigma_psi)^2 P.
//
// The state is given only when at least min_fixes fixes are kept and sigma_psi (the fit's
// part) is at most max_heading_sigma_rad: the vehicle has moved far enough, in a straight line
// or not, for the fixes to show its heading.
//
// With a heading sensor (the calibration's `heading`, an AHRS or compass; geometry/heading.h)
// the heading is measured instead: psi = wrap(h - heading(R_W_B(t_h) R_B_S e_x)) from its
// newest sample h at t_h on the path, sigma_psi^2 = sigma_h^2 + (gyro_bias_sigma (t - t_h))^2,
// and only c is fitted (3 n - 3 dof). Then min_fixes_with_heading fixes suffice: two by default,
// within about two seconds; one, the first fix, within about a second (it is measured at once and
// arrives 0.2-1 s late). A fix alone could be an outlier that nothing contradicts, so a state on
// a single fix has an outlier's size in its position covariance too, unconfirmed_fix_sigma_m per
// axis: the window's next fixes then pull it to the truth whether the first was good or not (a
// confident start on an outlier would gate the good fixes after it). One fix is not the default:
// a single 0.2 m fix breaks the long approach's error target more often than two, and the earlier
// start met a DVL rate test still locked by the start's tilt (README, "A heading sensor"). Fixes
// and DVL samples older than max_span_s before the newest fix are forgotten; so is everything
// before a DVL gap (bottom lock lost, a stop) longer than max_dvl_gap_s, since the path cannot be
// traced across it.
//
// Units: metres, radians, seconds; time stamps in ns.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "auvdock/estimator/imu_buffer.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/geometry/heading.h"
#include "auvdock/geometry/pose3.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"

namespace auvdock {

struct AcousticInitOptions {
  bool enabled = true;
  int min_fixes = 4;
  int min_fixes_with_heading = 2;  // with a heading sensor
  double unconfirmed_fix_sigma_m = 2.0;  // added to a start on one fix (an outlier's size)
  double max_span_s = 30.0;
  double max_dvl_gap_s = 1.0;
  double max_heading_sigma_rad = 0.1;  // about 6 degrees
  double gate_chi2 = 16.27;            // 3 dof, p = 0.999
  double tilt_sigma_rad = 0.03;        // an accelerating or rolling vehicle's tilt error
  double gyro_bias_sigma = 0.01;       // rad/s: the heading's drift from the unknown gyro bias
  double velocity_sigma_mps = 0.05;    // the DVL's velocity at the state (noise, a spike)
};

// A first state for the window.
struct InitialState {
  int64_t t_ns = 0;
  Pose3 T_D_B;
  Eigen::Vector3d v_D = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 6, 6> pose_covariance = Eigen::Matrix<double, 6, 6>::Identity();
  Eigen::Matrix3d velocity_covariance = Eigen::Matrix3d::Identity();
  int fixes_used = 0;       // fixes kept by the fit
  int fixes_rejected = 0;   // outliers dropped by the fit
  double heading_sigma_rad = 0.0;
  bool heading_measured = false;  // from the heading sensor, not the path
  bool unconfirmed = false;  // on one fix: its covariance covers an outlier (see above)
};

class AcousticInitializer {
 public:
  // Needs the calibration's DVL and acoustic sensors (without either, Solve never gives a state);
  // the dock's gravity and heading reference. Throws std::invalid_argument for options out of
  // range.
  AcousticInitializer(const Calibration& calibration, const DockModel& dock,
                      const AcousticInitOptions& options = {});

  // Samples in time order (an older sample than the newest is ignored); non-finite ones ignored.
  void AddFix(const AcousticFix& fix);
  void AddDvl(const DvlMeasurement& sample);
  void AddHeading(const HeadingMeasurement& sample);  // ignored without the heading sensor

  // True when a fix came since the last Solve (the caller tries again with each new fix).
  bool has_new_data() const { return has_new_data_; }
  // How long before t_ns samples must stay in the caller's IMU buffer.
  double imu_history_s() const { return options_.max_span_s + 1.0; }

  // The state at t_ns (at or after the newest DVL sample, within max_dvl_gap_s) from the fixes
  // and DVL samples so far and the IMU in imu; nullopt with the reason in *why.
  std::optional<InitialState> Solve(const ImuBuffer& imu, int64_t t_ns, std::string* why);

  const AcousticInitOptions& options() const { return options_; }

 private:
  bool usable_ = false;  // the calibration has both sensors
  Pose3 T_B_dvl_;
  Eigen::Vector3d p_B_transponder_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d gravity_direction_D_ = Eigen::Vector3d::UnitZ();
  std::optional<HeadingCalibration> heading_sensor_;
  HeadingReference heading_reference_;
  AcousticInitOptions options_;
  std::deque<AcousticFix> fixes_;
  std::deque<DvlMeasurement> dvl_;
  std::deque<HeadingMeasurement> headings_;
  bool has_new_data_ = false;
};

}  // namespace auvdock
