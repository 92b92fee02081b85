// Seed 001's rate-of-change test for the acoustic fixes, a second opinion before the chi-square
// gate: a fix that would have the vehicle move faster than it can since the last good fix is
// an outlier (a multipath or a wrong-channel reply), whatever the state's estimate.
//
// With the reference fix (p_r, sigma_r at t_r) and the new one (p, sigma at t),
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
  // The candidate at t_ns was kept by the estimator's gate: it becomes the reference.
  void Confirm(int64_t t_ns);
  void Reset() {
    reference_.reset();
    candidate_.reset();
  }

 private:
  struct Reference {
    AcousticFix fix;
    bool confirmed = false;  // passed a test itself
  };
  UsblRateTestOptions options_;
  std::optional<Reference> reference_, candidate_;
};

}  // namespace auvdock
