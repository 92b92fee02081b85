// Simulated AHRS / compass: the heading of the sensor's x axis (geometry/heading.h), with white
// noise, wrapped to (-pi, pi]:
//   h = wrap(heading(R_D_B R_B_S e_x) + n),   n ~ N(0, sigma_rad^2)
// the dock's heading_rad as the reference. Units: radians.
#pragma once

#include <random>

#include "auvdock/geometry/dock_model.h"
#include "auvdock/geometry/heading.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"
#include "auvdock/sim/docking_trajectory.h"

namespace auvdock {

class HeadingSimulator {
 public:
  HeadingSimulator(const HeadingCalibration& calibration, const DockModel& dock,
                   bool noise_enabled, std::mt19937_64 rng)
      : calibration_(calibration),
        reference_(HeadingReference::OfDock(dock)),
        noise_enabled_(noise_enabled),
        rng_(std::move(rng)) {}

  HeadingMeasurement Sample(int64_t t_ns, const KinematicState& s) {
    const Eigen::Vector3d a_D = s.T_D_B.q * (calibration_.T_B_S.q * Eigen::Vector3d::UnitX());
    double h = reference_.HeadingOf(a_D);
    if (noise_enabled_) h += std::normal_distribution<double>(0.0, calibration_.sigma_rad)(rng_);
    return {t_ns, WrapAngle(h)};
  }

 private:
  HeadingCalibration calibration_;
  HeadingReference reference_;
  bool noise_enabled_;
  std::mt19937_64 rng_;
};

}  // namespace auvdock
