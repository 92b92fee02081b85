// A pose with its timestamp: T_D_B (body in dock frame) at t_ns nanoseconds.
#pragma once

#include <cstdint>
#include <vector>

#include "auvdock/geometry/pose3.h"

namespace auvdock {

struct StampedPose {
  int64_t t_ns = 0;
  Pose3 T_D_B;
};

using Trajectory = std::vector<StampedPose>;

}  // namespace auvdock
