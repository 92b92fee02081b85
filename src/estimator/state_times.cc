#include "auvdock/estimator/state_times.h"

#include <cmath>
#include <stdexcept>

namespace auvdock {

std::vector<int64_t> StateTimesWithoutCameras(int64_t first_ns, int64_t last_ns, double rate_hz) {
  if (!std::isfinite(rate_hz) || !(rate_hz > 0.0)) {
    throw std::invalid_argument("StateTimesWithoutCameras: the rate must be finite and > 0");
  }
  std::vector<int64_t> times;
  const double period_ns = 1e9 / rate_hz;
  for (int64_t k = 1;; ++k) {
    const int64_t t = first_ns + std::llround(static_cast<double>(k) * period_ns);
    if (t > last_ns) break;
    times.push_back(t);
  }
  return times;
}

}  // namespace auvdock
