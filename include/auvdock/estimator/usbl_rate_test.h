// Seed 001's rate-of-change test for the acoustic measurements, a second opinion before the
// chi-square gate: a fix that would have the vehicle move faster than it can since the last good
// fix is an outlier (a multipath or a wrong-channel reply), whatever the state's estimate. The
// same for one SBL transducer's slant ranges (one test per transducer): a range changes no
// faster than the vehicle moves (the array turning with the hull adds |p_B| x the turn rate,
// well inside max_speed_mps's margin at docking speeds).
//
// With the reference (p_r, sigma_r at t_r) and the new measurement (p, sigma at t), p a fix's
// position or a range,
//   excess = (|p - p_r| - max_speed_mps (t - t_r)) / sqrt(sigma^2 + sigma_r^2)
// and the fix fails when excess > gate_sigmas. A fix that passes is a candidate; it becomes the
// reference when the estimator's gate keeps it too (Confirm). Against a reference that never
// passed a test itself, or without a reference (the first fix, or the last good one older than
// max_reference_age_s), the test has no opinion: the fix goes to the gate, and one bad first fix
// does not lock the test (the DVL's rate test, dvl_rate_test.h, works the same way).
// The speed bound is the vehicle's own: max_speed_mps, or more when the estimator knows the
// vehicle goes faster (SetEstimatedSpeed: its speed over ground plus speed_margin_mps, for the
// speed it may gain between the reference and the fix). A survey AUV at 1.8-2 m/s is not a
// docking vehicle at 0.5 m/s, and its good fixes must pass.
// Units: m, s.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "auvdock/io/measurements.h"

namespace auvdock {

struct UsblRateTestOptions {
  bool enabled = true;
  double max_speed_mps = 1.5;        // the vehicle's top speed over ground, with a margin
  double speed_margin_mps = 0.5;     // above the estimated speed (SetEstimatedSpeed)
  double gate_sigmas = 3.0;
  double max_reference_age_s = 10.0;
};

struct UsblRateVerdict {
  bool pass = true;
  double excess = 0.0;  // in sigmas (NaN without an opinion)
  std::string reason;   // why it failed; empty when it passed
};

class UsblRateTest {
 public:
  explicit UsblRateTest(const UsblRateTestOptions& options = {}) : options_(options) {}

  UsblRateVerdict Check(const AcousticFix& fix);
  UsblRateVerdict Check(const SblRange& range);
  // The candidate at t_ns was kept by the estimator's gate: it becomes the reference.
  void Confirm(int64_t t_ns);
  // The vehicle's estimated speed over ground (m/s): the bound becomes the larger of
  // max_speed_mps and speed + speed_margin_mps. A speed that is not finite is ignored.
  void SetEstimatedSpeed(double speed_mps) {
    if (std::isfinite(speed_mps)) estimated_speed_mps_ = std::max(0.0, speed_mps);
  }
  double speed_bound_mps() const {
    return std::max(options_.max_speed_mps, estimated_speed_mps_ + options_.speed_margin_mps);
  }
  void Reset() {
    reference_.reset();
    candidate_.reset();
  }

 private:
  struct Reference {
    int64_t t_ns = 0;
    Eigen::Vector3d value = Eigen::Vector3d::Zero();  // a fix's position, or (range, 0, 0)
    double sigma = 0.0;
    bool confirmed = false;  // passed a test itself
  };
  // what: "fix" or "range", for the reason.
  UsblRateVerdict CheckValue(int64_t t_ns, const Eigen::Vector3d& value, double sigma,
                             const char* what);
  UsblRateTestOptions options_;
  double estimated_speed_mps_ = 0.0;
  std::optional<Reference> reference_, candidate_;
};

}  // namespace auvdock
