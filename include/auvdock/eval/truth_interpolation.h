// The ground-truth state at any time of a log: interpolated between the two truth samples
// around it (the sample itself when the time falls on one). Position and velocity linear, the
// biases linear, the rotation by slerp (geometry/pose3.h Interpolate).
// Used by the evaluation (estimate poses against the truth) and by the Cramér-Rao bound (the
// true state at every frame).
#pragma once

#include <cstdint>
#include <vector>

#include "auvdock/io/measurements.h"

namespace auvdock {

enum class TruthLookup { kFound, kOutsideSpan, kInGap };

// `truth` in strictly increasing time. kOutsideSpan before the first or after the last sample;
// kInGap between two samples more than max_gap_s apart (compared in nanoseconds: a 10 Hz truth
// is not in a gap with max_gap_s = 0.1). `state` is written only when kFound.
TruthLookup InterpolateTruth(const std::vector<GroundTruthState>& truth, int64_t t_ns,
                             double max_gap_s, GroundTruthState* state);

}  // namespace auvdock
