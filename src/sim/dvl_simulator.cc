#include "auvdock/sim/dvl_simulator.h"

#include "auvdock/io/csv.h"
#include "auvdock/sim/random_stream.h"

namespace auvdock {

DvlSimulator::DvlSimulator(const DvlCalibration& calibration, const DvlFaultConfig& faults,
                           bool noise_enabled, std::mt19937_64 rng)
    : calibration_(calibration), faults_(faults), noise_enabled_(noise_enabled),
      rng_(std::move(rng)) {}

DvlMeasurement DvlSimulator::Sample(int64_t t_ns, const KinematicState& s,
                                    std::optional<FaultRecord>* fault) {
  fault->reset();
  const Eigen::Vector3d v_B = s.T_D_B.q.conjugate() * s.v_D + s.omega_B.cross(calibration_.T_B_S.p);
  DvlMeasurement m;
  m.t_ns = t_ns;
  m.v_S = calibration_.T_B_S.q.conjugate() * v_B;
  if (!noise_enabled_) return m;
  m.v_S += calibration_.sigma_mps * StandardNormal3(rng_);
  if (Uniform01(rng_) < faults_.gross_error_probability) {
    const Eigen::Vector3d direction = StandardNormal3(rng_).normalized();
    const double magnitude = faults_.gross_error_mps * (0.5 + 0.5 * Uniform01(rng_));
    const Eigen::Vector3d error = magnitude * direction;
    m.v_S += error;
    *fault = FaultRecord{t_ns, calibration_.name, "gross_error",
                         "dv=" + FormatDouble(error.x()) + ";" + FormatDouble(error.y()) + ";" +
                             FormatDouble(error.z())};
  }
  return m;
}

}  // namespace auvdock
