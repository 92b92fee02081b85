// The IMU's time base checked against its calibration: a log whose IMU time stamps are in
// seconds (or microseconds) instead of nanoseconds, or an IMU that runs at a rate far from the
// calibration's rate_hz, is a wrong input, not something to estimate through. Taken as given,
// time stamps in seconds made 41 distinct samples out of a 100 Hz log, and `run` went on to print
// "260 estimates, 118 GO" without a working IMU.
//
// The check: the median interval between consecutive samples (ns; robust to gaps and a few
// repeated stamps) against the calibration's 1e9 / rate_hz. Outside [1/2, 2] times it, the log
// is refused, with the likely cause when the median is off by a power of 1000 (a unit).
#pragma once

#include <string>
#include <vector>

#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"

namespace auvdock {

// Empty when the samples' rate agrees with calibration.rate_hz (or fewer than 10 samples: too
// few to tell), else why not, one line naming `file`.
std::string ImuTimeBaseProblem(const std::vector<ImuSample>& samples,
                               const ImuCalibration& calibration, const std::string& file);

}  // namespace auvdock
