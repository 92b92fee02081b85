// Simulated Doppler velocity log: velocity over ground of the DVL S, in S, with white noise and
// the faults real DVLs show (seed 003: gross errors at the 0.2 m/s level and above, some "close
// to normal values, long duration").
//
//   v_S = R_S_B (R_B_D v_D + w_B x p_B_S) + n + e,   n ~ N(0, sigma^2 I)
// Faults, each sample's reported as a FaultRecord (sensor = the DVL's name):
//  - "gross_error": a spike on one sample, random direction, magnitude uniform in
//    [0.5, 1] * gross_error_mps, with probability gross_error_probability per sample;
//  - "bias": a constant error of random direction and magnitude in [bias_min_mps,
//    bias_max_mps] lasting [bias_min_s, bias_max_s], starting at bias_rate_per_min on average
//    (a Poisson process; one episode at a time); every sample inside is listed;
//  - "bottom_lock_lost": no sample at all while the DVL's altitude above the deck/seabed plane
//    (z = 0 in D, z down: altitude = -z of p_D_S) is below min_altitude_m (a DVL's blanking
//    distance; 0 = never). A missing sample, not a bad one.
// Units: m/s, m, s.
#pragma once

#include <optional>
#include <random>

#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"
#include "auvdock/sim/docking_trajectory.h"

namespace auvdock {

struct DvlFaultConfig {
  double gross_error_probability = 0.02;
  double gross_error_mps = 0.6;
  double bias_rate_per_min = 0.0;
  double bias_min_mps = 0.2, bias_max_mps = 0.4;
  double bias_min_s = 1.0, bias_max_s = 5.0;
  double min_altitude_m = 0.3;
};

class DvlSimulator {
 public:
  DvlSimulator(const DvlCalibration& calibration, const DvlFaultConfig& faults,
               bool noise_enabled, std::mt19937_64 rng);
  // The measurement (nothing without bottom lock), and the fault record when the sample is
  // faulted or missing.
  std::optional<DvlMeasurement> Sample(int64_t t_ns, const KinematicState& s,
                                       std::optional<FaultRecord>* fault);

 private:
  DvlCalibration calibration_;
  DvlFaultConfig faults_;
  bool noise_enabled_;
  std::mt19937_64 rng_;
  int64_t last_t_ns_ = INT64_MIN;
  int64_t bias_end_ns_ = INT64_MIN;  // the current bias episode's end (INT64_MIN: none)
  Eigen::Vector3d bias_ = Eigen::Vector3d::Zero();
};

}  // namespace auvdock
