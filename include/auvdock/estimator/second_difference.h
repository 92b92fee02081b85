// A state-free innovation of a scalar sensor (the pressure depth, one SBL transducer's slant
// range), for estimating its effective noise online (adaptive_noise_scale.h), as the DVL's
// rate-of-change test is for the DVL.
//
// Three consecutive samples z0, z1, z2 at t0 < t1 < t2, each with its configured sigma s_i, give
// the second divided difference
//   d = c0 z0 + c1 z1 + c2 z2,   c0 = 2 / (h1 (h1 + h2)),  c2 = 2 / (h2 (h1 + h2)),  c1 = -c0 - c2
// (h1 = t1 - t0, h2 = t2 - t1): the quantity's second derivative at about t1 plus the noise.
// With white noise of sigma lambda^(1/2) s_i per sample,
//   Var d = lambda (c0^2 s0^2 + c1^2 s1^2 + c2^2 s2^2) + accel_sigma^2,
// where accel_sigma covers the quantity's own second derivative: a docking AUV's vertical
// acceleration, a few cm/s^2 (against a depth sigma of 2 cm at 10 Hz, sqrt(sum c^2) s ~ 5 m/s^2,
// it hardly counts); a slant range's, (v^2 - rdot^2) / r plus the acceleration along the line
// of sight, under 0.1 m/s^2 at 0.5 m/s and 5 m (against ~0.5 m/s^2 for 5 cm at 2 Hz).
// The statistic d^2 / Var d is chi-square with 1 dof when lambda is right, whatever the state's
// estimate. Samples more than max_span_s apart (a gap) restart the triple; a sample not later
// than the previous one, or not finite, is ignored. Units: those of the samples (m), s.
//
// Outliers (outlier_cutoff > 0): one bad sample z_k (an SBL multipath reply, a pressure spike)
// is in three triples, with weights 1, -2, 1: the middle one's statistic is 4x the others', so
// it is the one that shows the outlier, while the two beside it may look like plain noise and
// would bias the noise estimate. So a statistic above the cutoff is not returned, and neither
// are the one before it and the one after it; to allow that, each statistic is returned one
// sample late (and the one held at a gap is dropped).
#pragma once

#include <cstdint>
#include <optional>

namespace auvdock {

struct SecondDifferenceOptions {
  double accel_sigma = 0.1;  // of the quantity's second derivative (m/s^2)
  double max_span_s = 1.0;
  double outlier_cutoff = 0.0;  // statistic above which a sample is an outlier; 0: none
};

class SecondDifference {
 public:
  explicit SecondDifference(const SecondDifferenceOptions& options = {}) : options_(options) {}

  // The statistic of the triple ending with this sample (value, with its configured sigma > 0, at
  // t_ns), for the variance factor lambda in use; nullopt until there are three samples within
  // max_span_s. The sample then becomes the newest of the triple. With outlier_cutoff, the
  // statistic of the triple before (see above), or nullopt when it is left out.
  std::optional<double> Add(int64_t t_ns, double value, double sigma, double lambda);

  void Reset() {
    count_ = 0;
    held_.reset();
    drop_next_ = false;
  }

 private:
  // The outlier screen: the statistic to return for this one (see above).
  std::optional<double> Screen(std::optional<double> statistic);

  SecondDifferenceOptions options_;
  int64_t t_[2] = {0, 0};  // the two previous samples, older first
  double z_[2] = {0.0, 0.0};
  double s_[2] = {0.0, 0.0};
  int count_ = 0;          // how many of them are held (0-2)
  std::optional<double> held_;  // with outlier_cutoff: the statistic not yet returned
  bool drop_next_ = false;      // the next statistic shares an outlier's sample
};

}  // namespace auvdock
