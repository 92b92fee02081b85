#include "auvdock/sim/smooth_scalar.h"

namespace auvdock {

Smooth QuinticBlend(double t, double t0, double T, double p0, double v0, double p1) {
  const double tau = (t - t0) / T;
  if (tau <= 0.0) return {p0 + v0 * (t - t0), v0, 0.0};  // constant-velocity lead-in
  if (tau >= 1.0) return Smooth::Constant(p1);
  // Basis polynomials in tau and their tau-derivatives.
  const double t2 = tau * tau, t3 = t2 * tau, t4 = t3 * tau, t5 = t4 * tau;
  const double h0 = 1 - 10 * t3 + 15 * t4 - 6 * t5;
  const double h0d = -30 * t2 + 60 * t3 - 30 * t4;
  const double h0dd = -60 * tau + 180 * t2 - 120 * t3;
  const double h1 = tau - 6 * t3 + 8 * t4 - 3 * t5;
  const double h1d = 1 - 18 * t2 + 32 * t3 - 15 * t4;
  const double h1dd = -36 * tau + 96 * t2 - 60 * t3;
  const double h3 = 1.0 - h0, h3d = -h0d, h3dd = -h0dd;
  const double value = p0 * h0 + v0 * T * h1 + p1 * h3;
  const double dvalue = p0 * h0d + v0 * T * h1d + p1 * h3d;
  const double ddvalue = p0 * h0dd + v0 * T * h1dd + p1 * h3dd;
  return {value, dvalue / T, ddvalue / (T * T)};
}

}  // namespace auvdock
