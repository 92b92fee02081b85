// Simulated Doppler velocity log: velocity over ground of the DVL S, in S, with white noise and
// occasional gross errors (seed 003: DVL outliers at the 0.2 m/s level and above).
//
//   v_S = R_S_B (R_B_D v_D + w_B x p_B_S) + n,   n ~ N(0, sigma^2 I)
// A gross error adds a vector of random direction and magnitude uniform in
// [0.5, 1] * gross_error_mps; each one is reported as a FaultRecord. Units: m/s.
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
};

class DvlSimulator {
 public:
  DvlSimulator(const DvlCalibration& calibration, const DvlFaultConfig& faults,
               bool noise_enabled, std::mt19937_64 rng);
  // The measurement, and the fault record when a gross error was injected.
  DvlMeasurement Sample(int64_t t_ns, const KinematicState& s, std::optional<FaultRecord>* fault);

 private:
  DvlCalibration calibration_;
  DvlFaultConfig faults_;
  bool noise_enabled_;
  std::mt19937_64 rng_;
};

}  // namespace auvdock
