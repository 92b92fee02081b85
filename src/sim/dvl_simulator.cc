#include "auvdock/sim/dvl_simulator.h"

#include <cmath>

#include "auvdock/io/csv.h"
#include "auvdock/sim/random_stream.h"

namespace auvdock {
namespace {

std::string FormatVector(const Eigen::Vector3d& v) {
  return FormatDouble(v.x()) + ";" + FormatDouble(v.y()) + ";" + FormatDouble(v.z());
}

}  // namespace

DvlSimulator::DvlSimulator(const DvlCalibration& calibration, const DvlFaultConfig& faults,
                           bool noise_enabled, std::mt19937_64 rng)
    : calibration_(calibration), faults_(faults), noise_enabled_(noise_enabled),
      rng_(std::move(rng)) {}

std::optional<DvlMeasurement> DvlSimulator::Sample(int64_t t_ns, const KinematicState& s,
                                                   std::optional<FaultRecord>* fault) {
  fault->reset();
  const double dt_s = last_t_ns_ == INT64_MIN ? 0.0 : 1e-9 * static_cast<double>(t_ns - last_t_ns_);
  last_t_ns_ = t_ns;
  const double altitude_m = -(s.T_D_B * calibration_.T_B_S.p).z();
  if (faults_.min_altitude_m > 0.0 && altitude_m < faults_.min_altitude_m) {
    *fault = FaultRecord{t_ns, calibration_.name, "bottom_lock_lost",
                         "altitude_m=" + FormatDouble(altitude_m)};
    return std::nullopt;
  }
  const Eigen::Vector3d v_B = s.T_D_B.q.conjugate() * s.v_D + s.omega_B.cross(calibration_.T_B_S.p);
  DvlMeasurement m;
  m.t_ns = t_ns;
  m.v_S = calibration_.T_B_S.q.conjugate() * v_B;
  if (!noise_enabled_) return m;
  m.v_S += calibration_.sigma_mps * StandardNormal3(rng_);

  // A bias episode: ends at its time; a new one starts with probability rate * dt.
  if (t_ns >= bias_end_ns_) bias_end_ns_ = INT64_MIN;
  if (bias_end_ns_ == INT64_MIN && faults_.bias_rate_per_min > 0.0 &&
      Uniform01(rng_) < -std::expm1(-faults_.bias_rate_per_min / 60.0 * dt_s)) {
    bias_ = Uniform(rng_, faults_.bias_min_mps, faults_.bias_max_mps) *
            StandardNormal3(rng_).normalized();
    bias_end_ns_ = t_ns + static_cast<int64_t>(
                              1e9 * Uniform(rng_, faults_.bias_min_s, faults_.bias_max_s));
  }
  if (bias_end_ns_ != INT64_MIN) {
    m.v_S += bias_;
    *fault = FaultRecord{t_ns, calibration_.name, "bias", "dv=" + FormatVector(bias_)};
    return m;
  }
  if (Uniform01(rng_) < faults_.gross_error_probability) {
    const Eigen::Vector3d direction = StandardNormal3(rng_).normalized();
    const double magnitude = faults_.gross_error_mps * (0.5 + 0.5 * Uniform01(rng_));
    const Eigen::Vector3d error = magnitude * direction;
    m.v_S += error;
    *fault = FaultRecord{t_ns, calibration_.name, "gross_error", "dv=" + FormatVector(error)};
  }
  return m;
}

}  // namespace auvdock
