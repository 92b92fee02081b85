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
// Units: m, s.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "auvdock/io/measurements.h"

namespace auvdock {

struct UsblRateTestOptions {
  bool enabled = true;
  double max_speed_mps = 1.5;        // the vehicle's top speed over ground, with a margin
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
  std::optional<Reference> reference_, candidate_;
};

}  // namespace auvdock
