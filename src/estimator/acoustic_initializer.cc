#include "auvdock/estimator/acoustic_initializer.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

namespace auvdock {
namespace {

constexpr double kNsPerSecond = 1e9;

double Seconds(int64_t ns) { return static_cast<double>(ns) / kNsPerSecond; }

// A fix with the dead reckoning at its time.
struct FixOnPath {
  Eigen::Vector3d fix_D;
  double weight = 0.0;             // 1 / sigma^2
  Eigen::Vector3d d_W;             // the dead-reckoned position
  Eigen::Quaterniond q_W_B;        // the attitude in W
  double t_s = 0.0;                // since t0
  bool kept = true;
};

struct Fit {
  double psi = 0.0;
  Eigen::Vector3d b_bar = Eigen::Vector3d::Zero();
  Eigen::Vector3d d_bar = Eigen::Vector3d::Zero();
  double weight_sum = 0.0;
  double lever_information = 0.0;  // sum w |a|^2
  double t_bar_s = 0.0;
};

Eigen::Matrix3d AboutGravity(const Eigen::Vector3d& g, double psi) {
  return Eigen::AngleAxisd(psi, g).toRotationMatrix();
}

// The weighted Procrustes fit about g of the kept fixes (header), the lever arm at psi_lever.
Fit FitHeading(const std::vector<FixOnPath>& fixes, const Eigen::Vector3d& g,
               const Eigen::Vector3d& p_B_T, double psi_lever,
               std::vector<Eigen::Vector3d>* bodies) {
  Fit fit;
  const Eigen::Matrix3d R_lever = AboutGravity(g, psi_lever);
  bodies->assign(fixes.size(), Eigen::Vector3d::Zero());
  for (size_t i = 0; i < fixes.size(); ++i) {
    (*bodies)[i] = fixes[i].fix_D - R_lever * (fixes[i].q_W_B * p_B_T);
    if (!fixes[i].kept) continue;
    fit.weight_sum += fixes[i].weight;
    fit.b_bar += fixes[i].weight * (*bodies)[i];
    fit.d_bar += fixes[i].weight * fixes[i].d_W;
    fit.t_bar_s += fixes[i].weight * fixes[i].t_s;
  }
  fit.b_bar /= fit.weight_sum;
  fit.d_bar /= fit.weight_sum;
  fit.t_bar_s /= fit.weight_sum;
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - g * g.transpose();
  double s = 0.0, c = 0.0;
  for (size_t i = 0; i < fixes.size(); ++i) {
    if (!fixes[i].kept) continue;
    const Eigen::Vector3d a = P * (fixes[i].d_W - fit.d_bar);
    const Eigen::Vector3d e = P * ((*bodies)[i] - fit.b_bar);
    s += fixes[i].weight * g.dot(a.cross(e));
    c += fixes[i].weight * a.dot(e);
    fit.lever_information += fixes[i].weight * a.squaredNorm();
  }
  fit.psi = std::atan2(s, c);
  return fit;
}

}  // namespace

AcousticInitializer::AcousticInitializer(const Calibration& calibration, const DockModel& dock,
                                         const AcousticInitOptions& options)
    : heading_sensor_(calibration.heading), options_(options) {
  const Eigen::Vector3d& gravity_D = dock.gravity_D;
  if (options.min_fixes < 3 || options.min_fixes_with_heading < 1 ||
      !(options.unconfirmed_fix_sigma_m > 0.0) || !(options.max_span_s > 0.0) || !(options.max_dvl_gap_s > 0.0) ||
      !(options.max_heading_sigma_rad > 0.0) || !(options.gate_chi2 > 0.0) ||
      !(options.tilt_sigma_rad > 0.0) || !(options.gyro_bias_sigma >= 0.0) ||
      !(options.velocity_sigma_mps > 0.0)) {
    throw std::invalid_argument("AcousticInitOptions out of range");
  }
  if (!(gravity_D.norm() > 0.0)) throw std::invalid_argument("AcousticInitializer: zero gravity");
  gravity_direction_D_ = gravity_D.normalized();
  heading_reference_ = HeadingReference::OfDock(dock);
  usable_ = calibration.dvl.has_value() && calibration.acoustic.has_value();
  if (calibration.dvl) T_B_dvl_ = calibration.dvl->T_B_S;
  if (calibration.acoustic) p_B_transponder_ = calibration.acoustic->T_B_S.p;
}

void AcousticInitializer::AddFix(const AcousticFix& fix) {
  if (!fix.p_D.allFinite() || !(fix.sigma_m > 0.0) || !std::isfinite(fix.sigma_m)) return;
  if (!fixes_.empty() && fix.t_ns <= fixes_.back().t_ns) return;
  fixes_.push_back(fix);
  has_new_data_ = true;
  const int64_t oldest = fix.t_ns - static_cast<int64_t>(options_.max_span_s * kNsPerSecond);
  while (!fixes_.empty() && fixes_.front().t_ns < oldest) fixes_.pop_front();
  while (!dvl_.empty() && dvl_.front().t_ns < oldest) dvl_.pop_front();
  while (!headings_.empty() && headings_.front().t_ns < oldest) headings_.pop_front();
}

void AcousticInitializer::AddHeading(const HeadingMeasurement& sample) {
  if (!heading_sensor_ || !std::isfinite(sample.heading_rad)) return;
  if (!headings_.empty() && sample.t_ns <= headings_.back().t_ns) return;
  headings_.push_back(sample);
}

void AcousticInitializer::AddDvl(const DvlMeasurement& sample) {
  if (!sample.v_S.allFinite()) return;  // bottom lock lost: a gap
  if (!dvl_.empty() && sample.t_ns <= dvl_.back().t_ns) return;
  if (!dvl_.empty() &&
      Seconds(sample.t_ns - dvl_.back().t_ns) > options_.max_dvl_gap_s) {
    dvl_.clear();  // the path cannot be traced across the gap
  }
  dvl_.push_back(sample);
}

std::optional<InitialState> AcousticInitializer::Solve(const ImuBuffer& imu, int64_t t_ns,
                                                       std::string* why) {
  has_new_data_ = false;
  const auto fail = [&](const std::string& reason) -> std::optional<InitialState> {
    if (why) *why = "acoustic start: " + reason;
    return std::nullopt;
  };
  if (!usable_) return fail("needs the calibration's DVL and acoustic sensor");
  if (dvl_.size() < 2) return fail("fewer than 2 DVL samples since the last gap");
  if (t_ns < dvl_.back().t_ns || Seconds(t_ns - dvl_.back().t_ns) > options_.max_dvl_gap_s) {
    return fail("no recent DVL sample");
  }
  const Eigen::Vector3d& g = gravity_direction_D_;
  const int64_t t0 = dvl_.front().t_ns;
  const int64_t half_s = static_cast<int64_t>(0.25 * kNsPerSecond);
  const std::optional<Eigen::Vector3d> f_B = imu.MeanAccel(t0 - half_s, t0 + half_s, 3);
  if (!f_B || !(f_B->norm() > 0.0)) return fail("no IMU samples at the first DVL sample");
  // The tilt: the specific force of an unaccelerated vehicle is -g.
  const Eigen::Quaterniond q_W_B0 = Eigen::Quaterniond::FromTwoVectors(*f_B, -g);

  // Dead reckoning at each DVL sample.
  const ImuBias zero_bias;
  const Eigen::Matrix3d R_B_S = T_B_dvl_.q.toRotationMatrix();
  const Eigen::Vector3d& p_B_S = T_B_dvl_.p;
  std::vector<Eigen::Vector3d> d(dvl_.size()), v_W(dvl_.size());
  std::vector<Eigen::Quaterniond> q_W_B(dvl_.size());
  for (size_t k = 0; k < dvl_.size(); ++k) {
    if (k == 0) {
      q_W_B[k] = q_W_B0;
    } else {
      const std::optional<ImuPreintegration> pim =
          imu.Preintegrate(dvl_[k - 1].t_ns, dvl_[k].t_ns, zero_bias);
      if (!pim) return fail("the IMU does not cover the DVL samples");
      q_W_B[k] = (q_W_B[k - 1] * pim->delta_q()).normalized();
    }
    const Eigen::Vector3d w_B = imu.GyroAt(dvl_[k].t_ns).value_or(Eigen::Vector3d::Zero());
    const Eigen::Vector3d v_B = R_B_S * dvl_[k].v_S - w_B.cross(p_B_S);
    v_W[k] = q_W_B[k] * v_B;
    d[k] = k == 0 ? Eigen::Vector3d::Zero()
                  : Eigen::Vector3d(d[k - 1] + 0.5 * (v_W[k - 1] + v_W[k]) *
                                                   Seconds(dvl_[k].t_ns - dvl_[k - 1].t_ns));
  }

  // The fixes on the path (from the first DVL sample to a gap's length after the last).
  std::vector<FixOnPath> on_path;
  size_t k = 0;
  for (const AcousticFix& fix : fixes_) {
    if (fix.t_ns < t0) continue;
    const double after_last = Seconds(fix.t_ns - dvl_.back().t_ns);
    if (after_last > options_.max_dvl_gap_s) continue;
    while (k + 1 < dvl_.size() && dvl_[k + 1].t_ns <= fix.t_ns) ++k;
    FixOnPath p;
    p.fix_D = fix.p_D;
    p.weight = 1.0 / (fix.sigma_m * fix.sigma_m);
    p.t_s = Seconds(fix.t_ns - t0);
    p.q_W_B = q_W_B[k];
    if (k + 1 < dvl_.size()) {
      const double a = Seconds(fix.t_ns - dvl_[k].t_ns) / Seconds(dvl_[k + 1].t_ns - dvl_[k].t_ns);
      p.d_W = (1.0 - a) * d[k] + a * d[k + 1];
    } else {
      p.d_W = d[k] + v_W[k] * Seconds(fix.t_ns - dvl_[k].t_ns);
    }
    on_path.push_back(p);
  }
  // The heading sensor's newest sample on the path, turned into psi (header).
  std::optional<double> measured_psi;
  int64_t t_heading = 0;
  if (heading_sensor_) {
    for (auto it = headings_.rbegin(); it != headings_.rend(); ++it) {
      if (it->t_ns > t_ns || it->t_ns < t0) continue;
      size_t j = 0;
      while (j + 1 < dvl_.size() && dvl_[j + 1].t_ns <= it->t_ns) ++j;
      Eigen::Quaterniond q = q_W_B[j];
      if (it->t_ns > dvl_[j].t_ns) {
        const std::optional<ImuPreintegration> pim =
            imu.Preintegrate(dvl_[j].t_ns, it->t_ns, zero_bias);
        if (!pim) break;
        q = (q * pim->delta_q()).normalized();
      }
      const Eigen::Vector3d a_W = q * (heading_sensor_->T_B_S.q * Eigen::Vector3d::UnitX());
      measured_psi = WrapAngle(it->heading_rad - heading_reference_.HeadingOf(a_W));
      t_heading = it->t_ns;
      break;
    }
  }
  const int needed = measured_psi ? options_.min_fixes_with_heading : options_.min_fixes;
  const int n_on_path = static_cast<int>(on_path.size());
  if (n_on_path < needed) {
    return fail(std::to_string(n_on_path) + " fixes on the DVL's path, " +
                std::to_string(needed) + " needed");
  }

  // Fit, dropping the worst outlier while one is beyond the gate.
  std::vector<Eigen::Vector3d> bodies;
  Fit fit;
  int kept = n_on_path;
  double chi2_sum = 0.0;
  double worst_chi2 = 0.0;  // of the final fit
  while (true) {
    if (measured_psi) {
      fit = FitHeading(on_path, g, p_B_transponder_, *measured_psi, &bodies);
      fit.psi = *measured_psi;
    } else {
      fit = FitHeading(on_path, g, p_B_transponder_, 0.0, &bodies);
      fit = FitHeading(on_path, g, p_B_transponder_, fit.psi, &bodies);
    }
    const Eigen::Matrix3d R = AboutGravity(g, fit.psi);
    const Eigen::Vector3d c = fit.b_bar - R * fit.d_bar;
    int worst = -1;
    worst_chi2 = 0.0;
    chi2_sum = 0.0;
    for (int i = 0; i < n_on_path; ++i) {
      if (!on_path[i].kept) continue;
      const double chi2 = (bodies[i] - c - R * on_path[i].d_W).squaredNorm() * on_path[i].weight;
      chi2_sum += chi2;
      if (chi2 > worst_chi2) {
        worst_chi2 = chi2;
        worst = i;
      }
    }
    if (worst_chi2 <= options_.gate_chi2 || kept <= needed) break;
    on_path[worst].kept = false;
    --kept;
  }
  // Most fixes left out is no multipath (a few per cent of the replies): the fixes and the DVL's
  // path disagree as a whole (a DVL whose frame is not its T_B_S, turned 180 deg about z say,
  // against a measured heading; fixes in another frame than D). No start rather than one on the
  // two fixes that happen to agree with the wrong path.
  const int left_out = n_on_path - kept;
  if (left_out >= 3 && left_out > kept) {
    return fail(std::to_string(left_out) + " of " + std::to_string(n_on_path) +
                " fixes disagree with the DVL's path" +
                (measured_psi ? " under the measured heading" : std::string()) +
                ": check the DVL's frame (T_B_S) and the fixes' frame");
  }
  if (!measured_psi && !(fit.lever_information > 0.0)) return fail("the vehicle has not moved");
  const double fit_heading_sigma =
      measured_psi ? heading_sensor_->sigma_rad : 1.0 / std::sqrt(fit.lever_information);
  if (!measured_psi && fit_heading_sigma > options_.max_heading_sigma_rad) {
    char text[160];
    std::snprintf(text, sizeof(text),
                  "the path so far gives the heading to %.1f deg (at most %.1f): moving on",
                  fit_heading_sigma * 180.0 / M_PI, options_.max_heading_sigma_rad * 180.0 / M_PI);
    return fail(text);
  }
  // Still beyond the gate with only the fixes needed left: the fixes and the DVL disagree.
  if (worst_chi2 > options_.gate_chi2) return fail("the fixes and the DVL's path disagree");

  // The state at t_ns.
  const size_t last = dvl_.size() - 1;
  Eigen::Quaterniond q_W_Bt = q_W_B[last];
  if (t_ns > dvl_[last].t_ns) {
    const std::optional<ImuPreintegration> pim = imu.Preintegrate(dvl_[last].t_ns, t_ns, zero_bias);
    if (!pim) return fail("the IMU does not reach the state's time");
    q_W_Bt = (q_W_Bt * pim->delta_q()).normalized();
  }
  const Eigen::Vector3d d_t = d[last] + v_W[last] * Seconds(t_ns - dvl_[last].t_ns);
  const Eigen::Matrix3d R = AboutGravity(g, fit.psi);
  InitialState state;
  state.t_ns = t_ns;
  state.T_D_B = Pose3(Eigen::Quaterniond(R) * q_W_Bt, fit.b_bar + R * (d_t - fit.d_bar));
  state.T_D_B.q.normalize();
  state.v_D = R * v_W[last];
  state.fixes_used = kept;
  state.fixes_rejected = n_on_path - kept;
  state.heading_measured = measured_psi.has_value();

  // The gyro bias's heading drift since the heading's time (the fits' mean time, or the sample's).
  const double t_s = Seconds(t_ns - t0);
  const double drift = options_.gyro_bias_sigma *
                       (measured_psi ? Seconds(t_ns - t_heading) : t_s - fit.t_bar_s);
  const double var_psi = fit_heading_sigma * fit_heading_sigma + drift * drift;
  state.heading_sigma_rad = std::sqrt(var_psi);
  const int dof = 3 * kept - (measured_psi ? 3 : 4);  // 3 per fix; c (3) and psi (1) fitted
  const double variance_factor = std::max(1.0, dof > 0 ? chi2_sum / dof : 1.0);
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - g * g.transpose();
  const Eigen::Vector3d j = g.cross(R * (d_t - fit.d_bar));
  Eigen::Matrix<double, 6, 6> cov = Eigen::Matrix<double, 6, 6>::Zero();
  cov.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() / fit.weight_sum + var_psi * j * j.transpose();
  cov.topRightCorner<3, 3>() = var_psi * j * g.transpose();
  cov.bottomLeftCorner<3, 3>() = cov.topRightCorner<3, 3>().transpose();
  cov.bottomRightCorner<3, 3>() =
      options_.tilt_sigma_rad * options_.tilt_sigma_rad * P + var_psi * g * g.transpose();
  state.pose_covariance = variance_factor * cov;
  if (kept == 1) {
    state.unconfirmed = true;
    state.pose_covariance.topLeftCorner<3, 3>() +=
        options_.unconfirmed_fix_sigma_m * options_.unconfirmed_fix_sigma_m *
        Eigen::Matrix3d::Identity();
  }
  state.velocity_covariance =
      options_.velocity_sigma_mps * options_.velocity_sigma_mps * Eigen::Matrix3d::Identity() +
      var_psi * state.v_D.squaredNorm() * P;
  return state;
}

}  // namespace auvdock
