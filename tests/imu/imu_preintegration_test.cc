#include "auvdock/imu/imu_preintegration.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>

#include "auvdock/geometry/so3.h"
#include "auvdock/io/calibration.h"

namespace auvdock {
namespace {

const Eigen::Vector3d kGravity_D(0.0, 0.0, 9.81);

std::string Sci(double x) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3g", x);
  return text;
}

// Analytic, infinitely differentiable motion of B in D (z down), t in seconds:
//   p(t) = (1.0 t + 0.3 sin 1.3t,  0.8 sin 0.9t,  0.2 cos 0.6t)
//   R_D_B = Rz(yaw) Ry(pitch) Rx(roll), roll = 0.3 sin 1.2t, pitch = 0.2 sin(0.8t + 0.3),
//   yaw = 0.5 t + 0.4 sin 0.5t.
// Body rate from the Euler rates:
//   w_B = (droll, 0, 0) + Rx^T (0, dpitch, 0) + Rx^T Ry^T (0, 0, dyaw).
struct TruthSample {
  NavState state;
  Eigen::Vector3d gyro_B;
  Eigen::Vector3d accel_B;  // specific force f_B = R^T (a_D - g_D)
};

TruthSample Truth(double t) {
  const Eigen::Vector3d p(1.0 * t + 0.3 * std::sin(1.3 * t), 0.8 * std::sin(0.9 * t),
                          0.2 * std::cos(0.6 * t));
  const Eigen::Vector3d v(1.0 + 0.39 * std::cos(1.3 * t), 0.72 * std::cos(0.9 * t),
                          -0.12 * std::sin(0.6 * t));
  const Eigen::Vector3d a(-0.507 * std::sin(1.3 * t), -0.648 * std::sin(0.9 * t),
                          -0.072 * std::cos(0.6 * t));
  const double roll = 0.3 * std::sin(1.2 * t), droll = 0.36 * std::cos(1.2 * t);
  const double pitch = 0.2 * std::sin(0.8 * t + 0.3), dpitch = 0.16 * std::cos(0.8 * t + 0.3);
  const double yaw = 0.5 * t + 0.4 * std::sin(0.5 * t), dyaw = 0.5 + 0.2 * std::cos(0.5 * t);
  const Eigen::Matrix3d Rx = Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Matrix3d Ry = Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Quaterniond q = QuaternionFromRollPitchYaw(roll, pitch, yaw);
  TruthSample s;
  s.state.q_D_B = q;
  s.state.p_D = p;
  s.state.v_D = v;
  s.gyro_B = Eigen::Vector3d(droll, 0.0, 0.0) + Rx.transpose() * Eigen::Vector3d(0.0, dpitch, 0.0) +
             Rx.transpose() * Ry.transpose() * Eigen::Vector3d(0.0, 0.0, dyaw);
  s.accel_B = q.conjugate() * (a - kGravity_D);
  return s;
}

// Noise-free samples of Truth at t0, t0 + dt, ..., each held over dt, plus a constant bias.
ImuPreintegration IntegrateTruth(double t0, double duration, int rate_hz,
                                 const ImuBias& linearization_bias,
                                 const ImuBias& true_bias = ImuBias(),
                                 const ImuNoiseDensities& noise = ImuNoiseDensities()) {
  ImuPreintegration pim(noise, linearization_bias);
  const int n = static_cast<int>(std::lround(duration * rate_hz));
  const double dt = 1.0 / rate_hz;
  for (int k = 0; k < n; ++k) {
    const TruthSample s = Truth(t0 + k * dt);
    pim.Integrate(s.gyro_B + true_bias.gyro, s.accel_B + true_bias.accel, dt);
  }
  return pim;
}

// GTSAM testImuFactor.cpp, TEST(ImuFactor, PredictArbitrary): gravity 10 m/s^2 along +z of a
// z-down nav frame, a constant rate and specific force, 1000 samples of 1 ms, preintegrated about
// an accelerometer bias of (0.2, 0, 0) and predicted with zero bias (so the first-order bias
// correction has to undo the 0.2 exactly, which it can: dv, dp are linear in b_a).
TEST(ImuPreintegration, MatchesGtsamPredictArbitraryRegression) {
  ImuBias bias_hat;
  bias_hat.accel = Eigen::Vector3d(0.2, 0.0, 0.0);
  ImuPreintegration pim(ImuNoiseDensities(), bias_hat);
  const Eigen::Vector3d gyro(M_PI / 10, M_PI / 10, M_PI / 10);
  const Eigen::Vector3d accel(0.1, 0.2, -10.0);
  for (int i = 0; i < 1000; ++i) pim.Integrate(gyro, accel, 0.001);

  const NavState actual = pim.Predict(NavState(), ImuBias(), Eigen::Vector3d(0.0, 0.0, 10.0));

  Eigen::Matrix3d expected_R;
  expected_R << 0.903715275, -0.250741668, 0.347026393,  //
      0.347026393, 0.903715275, -0.250741668,            //
      -0.250741668, 0.347026393, 0.903715275;
  const Eigen::Vector3d expected_p(-0.516077031, 0.57842919, 0.0876478403);
  const Eigen::Vector3d expected_v(-1.62337767, 1.57954409, 0.343833571);
  const double r_err = (actual.q_D_B.toRotationMatrix() - expected_R).cwiseAbs().maxCoeff();
  const double p_err = (actual.p_D - expected_p).cwiseAbs().maxCoeff();
  const double v_err = (actual.v_D - expected_v).cwiseAbs().maxCoeff();
  EXPECT_LT(r_err, 1e-7);
  EXPECT_LT(p_err, 1e-7);
  EXPECT_LT(v_err, 1e-7);
  RecordProperty("max_rotation_error", Sci(r_err));
  RecordProperty("max_position_error", Sci(p_err));
  RecordProperty("max_velocity_error", Sci(v_err));
  EXPECT_NEAR(pim.sum_dt(), 1.0, 1e-12);
  EXPECT_EQ(pim.num_samples(), 1000);
}

struct PredictionError {
  double rotation = 0.0;  // rad
  double velocity = 0.0;  // m/s
  double position = 0.0;  // m
};

PredictionError ErrorAgainstTruth(int rate_hz, double t0, double duration) {
  const ImuPreintegration pim = IntegrateTruth(t0, duration, rate_hz, ImuBias());
  const NavState predicted = pim.Predict(Truth(t0).state, ImuBias(), kGravity_D);
  const NavState truth = Truth(t0 + duration).state;
  PredictionError e;
  e.rotation = LogQuaternion(truth.q_D_B.conjugate() * predicted.q_D_B).norm();
  e.velocity = (predicted.v_D - truth.v_D).norm();
  e.position = (predicted.p_D - truth.p_D).norm();
  return e;
}

// Euler with held samples is first order in all three deltas (the held rate and the held
// attitude each leave an O(dt) error per unit time): over a fixed interval the error shrinks
// linearly with dt. The bounds are C * dt with C from the trajectory's rates: the attitude error
// grows as 1/2 dt |dw/dt| t (|dw/dt| < 0.5 rad/s^2) and, times |f| ~ g, dominates the velocity
// and position errors (measured at 1 kHz: 2.7e-4 rad, 3.7e-3 m/s, 2.7e-3 m over 2 s). A wrong sign
// or frame anywhere shows up as an O(1) error instead.
TEST(ImuPreintegration, PredictsAnAnalyticTrajectoryToTheStepSizeAccuracy) {
  const double t0 = 0.7, duration = 2.0;
  const PredictionError e200 = ErrorAgainstTruth(200, t0, duration);
  const PredictionError e1000 = ErrorAgainstTruth(1000, t0, duration);
  for (const auto& [e, dt] : {std::pair{e200, 1.0 / 200}, std::pair{e1000, 1.0 / 1000}}) {
    EXPECT_LT(e.rotation, 0.5 * dt) << dt;
    EXPECT_LT(e.velocity, 10.0 * dt) << dt;
    EXPECT_LT(e.position, 10.0 * dt) << dt;
  }
  // First-order convergence: five times the rate, five times smaller (to within 10 %).
  EXPECT_NEAR(e200.rotation / e1000.rotation, 5.0, 0.5);
  EXPECT_NEAR(e200.velocity / e1000.velocity, 5.0, 0.5);
  EXPECT_NEAR(e200.position / e1000.position, 5.0, 0.5);
  RecordProperty("errors_1khz_rad_mps_m",
                 Sci(e1000.rotation) + " " + Sci(e1000.velocity) + " " + Sci(e1000.position));
}

TEST(ImuPreintegration, ZeroMotionGivesIdentityDeltasAndGravityOnlyPrediction) {
  ImuPreintegration pim(ImuNoiseDensities{}, ImuBias{});
  // At rest, level: the accelerometer reads -g in B.
  for (int i = 0; i < 200; ++i) pim.Integrate(Eigen::Vector3d::Zero(), -kGravity_D, 0.005);
  EXPECT_LT(LogQuaternion(pim.delta_q()).norm(), 1e-15);
  EXPECT_NEAR((pim.delta_v() - (-kGravity_D)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((pim.delta_p() - (-0.5 * kGravity_D)).norm(), 0.0, 1e-12);
  NavState start;
  start.p_D = Eigen::Vector3d(1.0, 2.0, 3.0);
  const NavState end = pim.Predict(start, ImuBias(), kGravity_D);
  EXPECT_LT((end.p_D - start.p_D).norm(), 1e-12);
  EXPECT_LT(end.v_D.norm(), 1e-12);
}

// Each bias Jacobian column against central differences of a full re-integration. The recursion
// is the exact derivative of the discrete scheme, so the agreement is at finite-difference
// precision, not only first order.
TEST(ImuPreintegration, BiasJacobiansMatchFiniteDifferencesOfReintegration) {
  ImuBias b0;
  b0.gyro = Eigen::Vector3d(0.01, -0.02, 0.015);
  b0.accel = Eigen::Vector3d(0.1, -0.05, 0.2);
  const double t0 = 0.3, duration = 1.5;
  const int rate = 200;
  const ImuPreintegration pim = IntegrateTruth(t0, duration, rate, b0);
  const double h = 1e-5;
  Eigen::Matrix3d J_theta_bg, J_v_bg, J_v_ba, J_p_bg, J_p_ba;
  for (int c = 0; c < 6; ++c) {
    ImuBias plus = b0, minus = b0;
    Eigen::Vector3d& plus_part = c < 3 ? plus.gyro : plus.accel;
    Eigen::Vector3d& minus_part = c < 3 ? minus.gyro : minus.accel;
    plus_part[c % 3] += h;
    minus_part[c % 3] -= h;
    const ImuPreintegration pp = IntegrateTruth(t0, duration, rate, plus);
    const ImuPreintegration pm = IntegrateTruth(t0, duration, rate, minus);
    const Eigen::Vector3d d_theta = (LogQuaternion(pim.delta_q().conjugate() * pp.delta_q()) -
                                     LogQuaternion(pim.delta_q().conjugate() * pm.delta_q())) /
                                    (2 * h);
    const Eigen::Vector3d d_v = (pp.delta_v() - pm.delta_v()) / (2 * h);
    const Eigen::Vector3d d_p = (pp.delta_p() - pm.delta_p()) / (2 * h);
    if (c < 3) {
      J_theta_bg.col(c) = d_theta;
      J_v_bg.col(c) = d_v;
      J_p_bg.col(c) = d_p;
    } else {
      EXPECT_LT(d_theta.norm(), 1e-12) << "the rotation does not depend on the accel bias";
      J_v_ba.col(c - 3) = d_v;
      J_p_ba.col(c - 3) = d_p;
    }
  }
  EXPECT_LT((pim.J_theta_bg() - J_theta_bg).norm(), 1e-7 * J_theta_bg.norm());
  EXPECT_LT((pim.J_v_bg() - J_v_bg).norm(), 1e-7 * J_v_bg.norm());
  EXPECT_LT((pim.J_v_ba() - J_v_ba).norm(), 1e-7 * J_v_ba.norm());
  EXPECT_LT((pim.J_p_bg() - J_p_bg).norm(), 1e-7 * J_p_bg.norm());
  EXPECT_LT((pim.J_p_ba() - J_p_ba).norm(), 1e-7 * J_p_ba.norm());

  // And the first-order correction: predicting with a bias db away from b0 differs from
  // re-integrating with it by the second-order remainder only, so halving db quarters the gap.
  const NavState start = Truth(t0).state;
  auto correction_gap = [&](double scale) {
    ImuBias b1 = b0;
    b1.gyro += scale * Eigen::Vector3d(2e-3, -1e-3, 1.5e-3);
    b1.accel += scale * Eigen::Vector3d(-0.01, 0.02, 0.01);
    const NavState corrected = pim.Predict(start, b1, kGravity_D);
    const NavState reintegrated =
        IntegrateTruth(t0, duration, rate, b1).Predict(start, b1, kGravity_D);
    return Eigen::Vector3d(LogQuaternion(corrected.q_D_B.conjugate() * reintegrated.q_D_B).norm(),
                           (corrected.v_D - reintegrated.v_D).norm(),
                           (corrected.p_D - reintegrated.p_D).norm());
  };
  const Eigen::Vector3d gap = correction_gap(1.0);
  const Eigen::Vector3d gap_half = correction_gap(0.5);
  // At db_g = 2.7e-3 rad/s over 1.5 s (4e-3 rad of attitude): gaps of order (4e-3)^2 |dv|.
  EXPECT_LT(gap[0], 1e-5);
  EXPECT_LT(gap[1], 2e-4);
  EXPECT_LT(gap[2], 2e-4);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(gap[i] / gap_half[i], 4.0, 0.2) << i;
}

// The propagated 9 x 9 covariance against the spread of 500 seeded noisy re-integrations. Noise is
// white per sample with sigma_c / sqrt(dt) (the discrete equivalent the propagation assumes); the
// error is measured in the covariance's own convention: dR_noisy = dR_clean Exp(dtheta).
TEST(ImuPreintegration, PropagatedCovarianceMatchesMonteCarloSpread) {
  ImuNoiseDensities noise;
  // Ten times the ADIS16448 figures so the spread is well above round-off, still linear.
  noise.gyroscope_noise_density = 3.4e-3;
  noise.accelerometer_noise_density = 4.0e-2;
  const double t0 = 0.2, duration = 1.0;
  const int rate = 200;
  const double dt = 1.0 / rate;
  const int n = static_cast<int>(duration * rate);
  const ImuPreintegration clean = IntegrateTruth(t0, duration, rate, ImuBias(), ImuBias(), noise);
  const Eigen::Matrix<double, 9, 9> P = clean.covariance();
  const Eigen::LLT<Eigen::Matrix<double, 9, 9>> llt(P);
  ASSERT_EQ(llt.info(), Eigen::Success);

  std::mt19937_64 rng(20170101);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double sg = noise.gyroscope_noise_density / std::sqrt(dt);
  const double sa = noise.accelerometer_noise_density / std::sqrt(dt);
  std::vector<TruthSample> samples;
  for (int k = 0; k < n; ++k) samples.push_back(Truth(t0 + k * dt));

  const int kRuns = 500;
  double nees_sum = 0.0;
  Eigen::Matrix<double, 9, 9> whitened_sum = Eigen::Matrix<double, 9, 9>::Zero();
  Eigen::Matrix<double, 9, 9> spread = Eigen::Matrix<double, 9, 9>::Zero();
  for (int run = 0; run < kRuns; ++run) {
    ImuPreintegration noisy(noise, ImuBias());
    for (const TruthSample& s : samples) {
      // One draw per statement: argument evaluation order is unspecified, and the seeded
      // sequence should give the same figures with every compiler.
      Eigen::Vector3d ng, na;
      for (int c = 0; c < 3; ++c) ng[c] = normal(rng);
      for (int c = 0; c < 3; ++c) na[c] = normal(rng);
      noisy.Integrate(s.gyro_B + sg * ng, s.accel_B + sa * na, dt);
    }
    Eigen::Matrix<double, 9, 1> e;
    e << LogQuaternion(clean.delta_q().conjugate() * noisy.delta_q()),
        noisy.delta_v() - clean.delta_v(), noisy.delta_p() - clean.delta_p();
    const Eigen::Matrix<double, 9, 1> w = llt.matrixL().solve(e);
    nees_sum += w.squaredNorm();
    whitened_sum += w * w.transpose();
    spread += e * e.transpose();
  }
  const double nees_mean = nees_sum / kRuns;
  // NEES ~ chi2(9) per run, so the sum ~ chi2(4500): the mean lies in 9 +- 2.58 sqrt(18 / 500)
  // = [8.51, 9.49] with 99 % probability.
  EXPECT_GT(nees_mean, 8.51);
  EXPECT_LT(nees_mean, 9.49);
  // Whitened sample covariance ~ I: entries have a standard deviation of about 0.045 (off
  // diagonal) to 0.063 (diagonal); 0.3 is ~5 sigma over the 45 distinct entries.
  const Eigen::Matrix<double, 9, 9> whitened = whitened_sum / kRuns;
  EXPECT_LT((whitened - Eigen::Matrix<double, 9, 9>::Identity()).cwiseAbs().maxCoeff(), 0.3)
      << whitened;
  // Per-axis standard deviations within 15 % (each variance has a 6.3 % standard deviation).
  const Eigen::Matrix<double, 9, 1> ratio =
      ((spread / kRuns).diagonal().array() / P.diagonal().array()).sqrt();
  EXPECT_LT((ratio.array() - 1.0).abs().maxCoeff(), 0.15) << ratio.transpose();
  RecordProperty("nees_mean", Sci(nees_mean));
  RecordProperty("whitened_max_deviation",
                 Sci((whitened - Eigen::Matrix<double, 9, 9>::Identity()).cwiseAbs().maxCoeff()));
  RecordProperty("sigma_ratio_min_max", Sci(ratio.minCoeff()) + " " + Sci(ratio.maxCoeff()));
}

TEST(ImuPreintegration, CovarianceGrowsAsTheTextbookFormulasForAStillLevelImu) {
  // At rest and level, dv = sum of dt a-noise: var = sigma_a^2 T per axis; dtheta likewise with
  // sigma_g; dp ~ sigma_a^2 T^3 / 3 (to O(dt)).
  ImuNoiseDensities noise;
  ImuPreintegration pim(noise, ImuBias());
  const double dt = 0.001, T = 2.0;
  for (int i = 0; i < 2000; ++i)
    pim.Integrate(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), dt);
  const double sa2 = noise.accelerometer_noise_density * noise.accelerometer_noise_density;
  const double sg2 = noise.gyroscope_noise_density * noise.gyroscope_noise_density;
  EXPECT_NEAR(pim.covariance()(0, 0), sg2 * T, 1e-12 * sg2);
  EXPECT_NEAR(pim.covariance()(3, 3), sa2 * T, 1e-9 * sa2);
  EXPECT_NEAR(pim.covariance()(6, 6), sa2 * T * T * T / 3.0, 1e-3 * sa2 * T * T * T / 3.0);
  EXPECT_NEAR(pim.covariance()(6, 3), sa2 * T * T / 2.0, 1e-3 * sa2 * T * T / 2.0);
}

// One held sample (a frame time just past the IMU's last sample): the discrete model alone
// makes dv and dp one noise (a singular covariance, which the IMU factor cannot whiten); over
// the piece the noise is continuous, which gives the exact (dv, dp) covariance and a positive
// definite whole. Summed over many pieces it is the continuous result without the O(dt) error.
TEST(ImuPreintegration, OnePieceHasTheContinuousNoiseCovarianceAndIsPositiveDefinite) {
  ImuNoiseDensities noise;
  ImuPreintegration pim(noise, ImuBias());
  const double dt = 0.037;
  pim.Integrate(Eigen::Vector3d(0.01, -0.02, 0.03), Eigen::Vector3d(0.1, 0.2, -9.81), dt);
  const double sa2 = noise.accelerometer_noise_density * noise.accelerometer_noise_density;
  const Eigen::Matrix<double, 9, 9>& P = pim.covariance();
  const Eigen::LLT<Eigen::Matrix<double, 9, 9>> llt(P);
  EXPECT_EQ(llt.info(), Eigen::Success);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(P(3 + i, 3 + i), sa2 * dt, 1e-12 * sa2 * dt);
    EXPECT_NEAR(P(6 + i, 6 + i), sa2 * dt * dt * dt / 3.0, 1e-12 * sa2 * dt * dt * dt);
    EXPECT_NEAR(P(6 + i, 3 + i), sa2 * dt * dt / 2.0, 1e-12 * sa2 * dt * dt);
  }

  ImuPreintegration still(noise, ImuBias());
  const double step = 0.001, T = 2.0;
  for (int i = 0; i < 2000; ++i) {
    still.Integrate(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), step);
  }
  EXPECT_NEAR(still.covariance()(6, 6), sa2 * T * T * T / 3.0, 1e-9 * sa2 * T * T * T / 3.0);
}

TEST(ImuPreintegration, RejectsBadInput) {
  ImuNoiseDensities bad = ImuNoiseDensities();
  bad.gyroscope_noise_density = -1.0;
  EXPECT_THROW(ImuPreintegration(bad, ImuBias()), std::invalid_argument);
  bad = ImuNoiseDensities();
  bad.accelerometer_random_walk = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(ImuPreintegration(bad, ImuBias()), std::invalid_argument);
  ImuBias nan_bias;
  nan_bias.accel.x() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(ImuPreintegration(ImuNoiseDensities(), nan_bias), std::invalid_argument);

  ImuPreintegration pim(ImuNoiseDensities{}, ImuBias{});
  const Eigen::Vector3d ok(0.1, 0.2, -9.8);
  EXPECT_THROW(pim.Integrate(ok, ok, 0.0), std::invalid_argument);
  EXPECT_THROW(pim.Integrate(ok, ok, -0.005), std::invalid_argument);
  EXPECT_THROW(pim.Integrate(ok, ok, std::numeric_limits<double>::quiet_NaN()),
               std::invalid_argument);
  EXPECT_THROW(pim.Integrate(Eigen::Vector3d(0, std::nan(""), 0), ok, 0.005),
               std::invalid_argument);
  EXPECT_THROW(pim.Integrate(ok, Eigen::Vector3d::Constant(HUGE_VAL), 0.005),
               std::invalid_argument);
  EXPECT_EQ(pim.num_samples(), 0);  // rejected samples leave no trace
  EXPECT_EQ(pim.sum_dt(), 0.0);
}

TEST(ImuPreintegration, ResetStartsAgainAboutTheNewBias) {
  ImuPreintegration pim(ImuNoiseDensities{}, ImuBias{});
  for (int i = 0; i < 10; ++i)
    pim.Integrate(Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d(1, 0, 0), 0.01);
  ImuBias b;
  b.gyro = Eigen::Vector3d(0.05, 0.0, 0.0);
  pim.Reset(b);
  EXPECT_EQ(pim.num_samples(), 0);
  EXPECT_EQ(pim.sum_dt(), 0.0);
  EXPECT_EQ(pim.covariance().norm(), 0.0);
  EXPECT_EQ(pim.linearization_bias().gyro, b.gyro);
  pim.Integrate(Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d::Zero(), 1.0);
  EXPECT_NEAR(LogQuaternion(pim.delta_q()).x(), 0.05, 1e-15);
}

TEST(ImuPreintegration, NoiseDensitiesComeFromTheCalibration) {
  ImuCalibration calibration;
  calibration.gyroscope_noise_density = 1.0;
  calibration.gyroscope_random_walk = 2.0;
  calibration.accelerometer_noise_density = 3.0;
  calibration.accelerometer_random_walk = 4.0;
  const ImuNoiseDensities noise = ImuNoiseDensities::FromCalibration(calibration);
  EXPECT_EQ(noise.gyroscope_noise_density, 1.0);
  EXPECT_EQ(noise.gyroscope_random_walk, 2.0);
  EXPECT_EQ(noise.accelerometer_noise_density, 3.0);
  EXPECT_EQ(noise.accelerometer_random_walk, 4.0);
}

// Jr and its inverse: Jr(phi) Jr^-1(phi) = I for small and large angles, and Jr^-1 is the
// derivative of Log at Exp(phi) along a right perturbation (numerically, central differences).
TEST(InverseRightJacobianSO3, InvertsTheRightJacobianAndDifferentiatesLog) {
  std::mt19937_64 rng(31);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (const double angle : {0.0, 1e-7, 1e-3, 0.3, 1.5, 2.8}) {
    Eigen::Vector3d axis(normal(rng), normal(rng), normal(rng));
    const Eigen::Vector3d phi = angle * axis.normalized();
    const Eigen::Matrix3d product = RightJacobianSO3(phi) * InverseRightJacobianSO3(phi);
    EXPECT_LT((product - Eigen::Matrix3d::Identity()).norm(), 1e-12) << angle;
    if (angle < 1e-6) continue;
    const double h = 1e-6;
    Eigen::Matrix3d numeric;
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d d = h * Eigen::Vector3d::Unit(c);
      numeric.col(c) = (LogSO3(ExpSO3(phi) * ExpSO3(d)) - LogSO3(ExpSO3(phi) * ExpSO3(-d))) /
                       (2.0 * h);
    }
    EXPECT_LT((numeric - InverseRightJacobianSO3(phi)).norm(), 1e-7) << angle;
  }
}

}  // namespace
}  // namespace auvdock
