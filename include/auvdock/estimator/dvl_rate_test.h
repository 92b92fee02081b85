// Seed 001's rate-of-change test, for the DVL: a second opinion next to the chi-square gate,
// which cannot catch a sample that is the only one constraining the velocity (the first sample
// after start or a reset, a long outage: the solve simply fits it), nor a long, small bias once
// it has pulled the window.
//
// Each sample is predicted from the last sample that passed (the reference, at t_r) and the
// IMU's velocity change since (the gyro's rotation and the specific force, at the state's bias):
//   v_B(t_r) = R_B_S v_S(t_r) - w_B(t_r) x p_B_S
//   v_B(t)   = dR^T (v_B(t_r) + dv) + R_Bt_D g_D dt        (dR = R_Br_Bt, dv: preintegrated)
//   v_S(t)   = R_S_B (v_B(t) + w_B(t) x p_B_S)
// and the whitened difference d = v_S - v_S(t) predicted, with covariance
//   (2 lambda sigma^2 + ((accel_sigma^2 + s^2) dt^2)) I
// (two samples' noise, lambda the adaptive variance factor, SetNoiseFactor; the IMU's unmodelled
// part per second, accel_sigma; and s, the state's own uncertainty of what the prediction leans
// on, SetStateUncertainty: |g| times the tilt's sigma and the accelerometer bias's. Right after a
// start the tilt is known to ~0.03 rad, 0.3 m/s^2 on g: without s, a DVL sample 0.2 s after its
// reference failed by 18 sigma, and every clean sample was rejected for 3 s.)
// is tested against gate_chi2 (3 dof). A sample that passes is a candidate; it becomes the
// reference when the estimator's own chi-square gate keeps it as well (Confirm), so that a
// long bias the rate test lets through once the reference has aged is not the next reference
// if the other sensors disagree with it. A sample that fails against a confirmed reference is
// rejected.
//
// A sample that cannot be tested (no reference: the first after a start, a gap or a reference
// that aged out) or that fails against a reference that never passed a test itself is neither
// passed nor rejected: it is held (verdict.held) and becomes the unconfirmed reference, and the
// next sample decides. If that one agrees with it, the held sample is released to the estimator
// (verdict.released, used late at its own time: causal) with the new one; if not, of two
// samples that disagree either may be the spike, so the held one is rejected
// (verdict.dropped) and the new one is held in its place. So the test waits for two samples in
// a row that agree. One bad first sample does not lock the test, and a spike right after the
// first sample is not let through: at the start the velocity has no other constraint, so the
// gate would keep it, and the spike would become the reference that rejects every clean sample
// after it (seed 37 of the Monte-Carlo audit, DVL spikes at 3x the default rate: 0.37 m/s at
// 0.2 s, every sample rejected for 3 s, 43 unsafe GO). Holding instead of rejecting spares the
// first clean sample after a start or a fault (sensor_faults.yaml, seeds 1-3: 9 clean samples
// of 450 were rejected so, 2 %, against the 1 %); the price is one DVL period of delay
// for that one sample.
// A reference older than max_reference_age_s is dropped (the test has little power left: the
// IMU's velocity error over that time nears the size of the faults it looks for), so a sensor
// that has really changed is accepted again after that time if the other sensors agree; a held
// one that old is rejected (ExpireHeld: no sample came to test it against). A sample still held
// when the run ends is neither used nor reported, like the samples after the last frame.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "auvdock/estimator/imu_buffer.h"
#include "auvdock/geometry/pose3.h"
#include "auvdock/imu/imu_preintegration.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"

namespace auvdock {

struct DvlRateTestOptions {
  bool enabled = true;
  double gate_chi2 = 16.27;          // 3 dof, p = 0.999
  double accel_sigma_mps2 = 0.02;    // the IMU's unmodelled velocity error per second
  double max_reference_age_s = 3.0;
};

struct DvlRateVerdict {
  bool pass = false;
  bool held = false;       // neither passed nor rejected: the next sample decides
  double statistic = 0.0;  // chi-square (NaN without a reference)
  std::string reason;      // why it failed or is held; empty when it passed
  // An earlier held sample: agreed with by this one (released: use it now, at its own time), or
  // disagreed with (dropped: reject it, for dropped_reason).
  std::optional<DvlMeasurement> released;
  std::optional<DvlMeasurement> dropped;
  std::string dropped_reason;
};

class DvlRateTest {
 public:
  DvlRateTest(const DvlCalibration& calibration, const DvlRateTestOptions& options)
      : calibration_(calibration), options_(options) {}

  // The sample at its time, with the IMU, the bias and the body attitude R_D_B at that time.
  DvlRateVerdict Check(const DvlMeasurement& sample, const ImuBuffer& imu, const ImuBias& bias,
                       const Eigen::Quaterniond& q_D_B, const Eigen::Vector3d& gravity_D);

  // The candidate at t_ns (a sample that passed Check) was kept by the estimator's gate: it
  // becomes the reference. Candidates that are never confirmed are dropped by the next Check.
  void Confirm(int64_t t_ns);

  // The DVL's variance factor in use (adaptive_noise_scale.h: its effective noise over the
  // configured sigma, squared): the samples' part of the variance above is 2 factor sigma^2.
  void SetNoiseFactor(double factor) { noise_factor_ = factor > 0.0 ? factor : 1.0; }
  // s above (m/s^2): the estimator's current uncertainty of g in B and of the accelerometer bias.
  void SetStateUncertainty(double accel_sigma_mps2) {
    state_accel_sigma_ = accel_sigma_mps2 >= 0.0 ? accel_sigma_mps2 : 0.0;
  }

  // The held sample, if it is older than max_reference_age_s at now_ns (rejected: nothing came
  // to test it against); it is forgotten.
  std::optional<DvlMeasurement> ExpireHeld(int64_t now_ns);

  // Forgets the reference (after a reset of the estimator).
  void Reset() {
    reference_.reset();
    candidate_.reset();
  }

 private:
  struct Reference {
    DvlMeasurement sample;
    Eigen::Vector3d w_B = Eigen::Vector3d::Zero();
    bool confirmed = false;  // passed a test itself
    bool held = false;       // its own verdict waits for the next sample
  };
  double noise_factor_ = 1.0;
  double state_accel_sigma_ = 0.0;

  DvlCalibration calibration_;
  DvlRateTestOptions options_;
  std::optional<Reference> reference_;
  std::optional<Reference> candidate_;
};

}  // namespace auvdock
