// A measurement the estimator did not use, and why: one row of OUTDIR/rejections.csv
// (`timestamp_ns, sensor, statistic, reason`). The statistic is the squared whitened residual
// (chi-square) for a gated measurement, NaN where there is none (a sample out of order, not
// finite, or without a state at its time).
#pragma once

#include <cstdint>
#include <limits>
#include <string>

namespace auvdock {

struct Rejection {
  int64_t t_ns = 0;      // the measurement's own time
  std::string sensor;    // the calibration's sensor name (cam0, depth0, dvl0, ...)
  double statistic = 0.0;
  std::string reason;
};

// The statistic of a rejection without one.
inline constexpr double kNoStatistic = std::numeric_limits<double>::quiet_NaN();
// The reason of a sensor sample that found no state to attach to.
inline constexpr const char* kNoStateReason =
    "no state at or before its time or the IMU does not reach it";
// ... of one from before the sliding window's first state since its last initialisation.
// ... of a DVL sample the rate test held (dvl_rate_test.h) that no later sample came to test.
inline constexpr const char* kHeldDvlExpiredReason =
    "rate test: held, and no sample within the reference age came to test it against";
// ... of a DVL sample before the DVL's admission (EstimatorOptions::dvl_admission) that
// disagreed with the window's velocity, and of one the window could not test yet.
inline constexpr const char* kDvlNotAdmittedReason =
    "before admission: disagrees with the window's velocity without it";
inline constexpr const char* kDvlUntestableReason =
    "before admission: the window's velocity cannot test it yet";
inline constexpr const char* kBeforeFirstStateReason =
    "before the estimator's first state (it initialised after this sample)";

}  // namespace auvdock
