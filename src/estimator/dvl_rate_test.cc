#include "auvdock/estimator/dvl_rate_test.h"

#include <cmath>
#include <limits>

#include "auvdock/estimator/rejection.h"

namespace auvdock {

DvlRateVerdict DvlRateTest::Check(const DvlMeasurement& sample, const ImuBuffer& imu,
                                  const ImuBias& bias, const Eigen::Quaterniond& q_D_B,
                                  const Eigen::Vector3d& gravity_D) {
  DvlRateVerdict verdict;
  if (!options_.enabled) {
    verdict.pass = true;
    return verdict;
  }
  const std::optional<Eigen::Vector3d> gyro = imu.GyroAt(sample.t_ns);
  const Eigen::Vector3d w_B = gyro ? Eigen::Vector3d(*gyro - bias.gyro) : Eigen::Vector3d::Zero();
  const auto hold = [&](const std::string& reason) {
    verdict.held = true;
    verdict.reason = reason;
    reference_ = Reference{sample, w_B, /*confirmed=*/false, /*held=*/true};
  };
  candidate_.reset();
  if (reference_ &&
      1e-9 * static_cast<double>(sample.t_ns - reference_->sample.t_ns) >
          options_.max_reference_age_s) {
    if (reference_->held) {
      verdict.dropped = reference_->sample;
      verdict.dropped_reason = kHeldDvlExpiredReason;
    }
    reference_.reset();
  }
  const std::optional<ImuPreintegration> pim =
      reference_ ? imu.Preintegrate(reference_->sample.t_ns, sample.t_ns, bias) : std::nullopt;
  if (!reference_ || !pim || !gyro) {
    if (reference_ && reference_->held) {
      verdict.dropped = reference_->sample;
      verdict.dropped_reason = kHeldDvlExpiredReason;
    }
    verdict.statistic = std::numeric_limits<double>::quiet_NaN();
    hold("rate test: no reference sample within " + std::to_string(options_.max_reference_age_s) +
         " s (the first after a start or a gap): held for the next sample");
    return verdict;
  }
  const Eigen::Quaterniond q_B_S = calibration_.T_B_S.q.normalized();
  const Eigen::Vector3d& p_B_S = calibration_.T_B_S.p;
  const double dt = pim->sum_dt();
  const Eigen::Vector3d v_B_ref = q_B_S * reference_->sample.v_S - reference_->w_B.cross(p_B_S);
  const Eigen::Vector3d v_B = pim->delta_q().conjugate() * (v_B_ref + pim->delta_v()) +
                              q_D_B.conjugate() * gravity_D * dt;
  const Eigen::Vector3d predicted = q_B_S.conjugate() * (v_B + w_B.cross(p_B_S));
  const double variance =
      2.0 * noise_factor_ * calibration_.sigma_mps * calibration_.sigma_mps +
      (options_.accel_sigma_mps2 * options_.accel_sigma_mps2 +
       state_accel_sigma_ * state_accel_sigma_) *
          dt * dt;
  verdict.statistic = (sample.v_S - predicted).squaredNorm() / variance;
  verdict.pass = verdict.statistic <= options_.gate_chi2;
  if (verdict.pass) {
    if (reference_->held) {  // the held sample is confirmed by this one
      verdict.released = reference_->sample;
      reference_->held = false;
    }
    candidate_ = Reference{sample, w_B, true, false};
  } else if (!reference_->confirmed) {
    // Two samples that disagree, the older never tested itself: either may be the spike, so
    // neither is trusted. The older one is rejected, the newer waits for a sample that agrees.
    if (reference_->held) {
      verdict.dropped = reference_->sample;
      verdict.dropped_reason = "rate test: disagrees with the next sample, neither of them tested";
    }
    hold("rate test: disagrees with the previous sample, itself untested: held for the next");
  } else {
    verdict.reason = "rate test: jump against the IMU since the last good sample";
  }
  return verdict;
}

std::optional<DvlMeasurement> DvlRateTest::ExpireHeld(int64_t now_ns) {
  if (!reference_ || !reference_->held ||
      !(1e-9 * static_cast<double>(now_ns - reference_->sample.t_ns) >
        options_.max_reference_age_s)) {
    return std::nullopt;
  }
  const DvlMeasurement held = reference_->sample;
  reference_.reset();
  return held;
}

void DvlRateTest::Confirm(int64_t t_ns) {
  if (candidate_ && candidate_->sample.t_ns == t_ns) {
    reference_ = candidate_;
    candidate_.reset();
  }
}

}  // namespace auvdock
