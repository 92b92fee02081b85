#include "auvdock/io/imu_time_base.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace auvdock {

std::string ImuTimeBaseProblem(const std::vector<ImuSample>& samples,
                               const ImuCalibration& calibration, const std::string& file) {
  constexpr size_t kMinSamples = 10;
  if (samples.size() < kMinSamples || !(calibration.rate_hz > 0.0)) return {};
  std::vector<double> intervals_ns;
  intervals_ns.reserve(samples.size() - 1);
  for (size_t k = 1; k < samples.size(); ++k) {
    intervals_ns.push_back(static_cast<double>(samples[k].t_ns - samples[k - 1].t_ns));
  }
  const auto middle = intervals_ns.begin() + static_cast<std::ptrdiff_t>(intervals_ns.size() / 2);
  std::nth_element(intervals_ns.begin(), middle, intervals_ns.end());
  const double median_ns = *middle;
  const double expected_ns = 1e9 / calibration.rate_hz;
  const double ratio = median_ns / expected_ns;
  if (ratio >= 0.5 && ratio <= 2.0) return {};
  // A unit's factor within a factor of 10 either way.
  const auto near_power = [&](double exponent) {
    return std::abs(std::log10(std::max(ratio, 1e-300)) - exponent) < 1.0;
  };
  std::string cause = ": the calibration's rate_hz or the log is not this IMU's";
  if (ratio > 2.0 && std::fmod(median_ns, 1e9) == 0.0) {
    // Whole seconds written as nanoseconds: the samples within a second share a stamp and only
    // one per second is left (the others are skipped as repeated).
    cause = ": time stamps in whole seconds instead of nanoseconds?";
  } else if (near_power(-6.0)) {
    cause = ": time stamps in milliseconds instead of nanoseconds?";
  } else if (near_power(-3.0)) {
    cause = ": time stamps in microseconds instead of nanoseconds?";
  }
  char text[320];
  std::snprintf(text, sizeof(text),
                "%s: IMU samples are %.3g ns apart (median), where the calibration's rate_hz %g "
                "says %.3g ns (%.3g Hz against %g Hz)%s",
                file.c_str(), median_ns, calibration.rate_hz, expected_ns,
                median_ns > 0.0 ? 1e9 / median_ns : 0.0, calibration.rate_hz, cause.c_str());
  return text;
}

}  // namespace auvdock
