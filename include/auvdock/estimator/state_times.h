// The times of the estimator's states on a log without camera frames (an IMU with any of DVL,
// depth, acoustic fixes, ranges and a heading sensor: a navigator's log). The window and the
// smoother keep a state per camera frame; without cameras they need states of their own, at a
// steady rate over the IMU's span, so that every navigation sample meets a state at or before its
// time (estimator/sensor_factors.h) and the controller gets an estimate at that rate.
//
// t_k = first_ns + k / rate_hz for k = 1, 2, ... while t_k <= last_ns (the first state one period
// after the first IMU sample, so that its tilt check has IMU samples before it). ns.
#pragma once

#include <cstdint>
#include <vector>

namespace auvdock {

// Throws std::invalid_argument for a rate that is not finite and positive.
std::vector<int64_t> StateTimesWithoutCameras(int64_t first_ns, int64_t last_ns, double rate_hz);

}  // namespace auvdock
