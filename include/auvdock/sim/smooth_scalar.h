// A scalar function of time carried with its first two time derivatives: (f, f', f'').
//
// Arithmetic follows the chain and product rules exactly, e.g.
//   (f g)'' = f'' g + 2 f' g' + f g'',   sin(f)'' = cos(f) f'' - sin(f) f'^2,
// so a trajectory written as an expression of Smooth values yields exact velocities and
// accelerations (and hence exact IMU signals) without finite differences.
#pragma once

#include <cmath>

namespace auvdock {

struct Smooth {
  double v = 0.0;   // value
  double d = 0.0;   // first derivative
  double dd = 0.0;  // second derivative

  static Smooth Constant(double c) { return {c, 0.0, 0.0}; }
  // The identity function of time, t -> t.
  static Smooth Time(double t) { return {t, 1.0, 0.0}; }
};

inline Smooth operator+(const Smooth& a, const Smooth& b) {
  return {a.v + b.v, a.d + b.d, a.dd + b.dd};
}
inline Smooth operator-(const Smooth& a, const Smooth& b) {
  return {a.v - b.v, a.d - b.d, a.dd - b.dd};
}
inline Smooth operator-(const Smooth& a) { return {-a.v, -a.d, -a.dd}; }
inline Smooth operator*(const Smooth& a, const Smooth& b) {
  return {a.v * b.v, a.d * b.v + a.v * b.d, a.dd * b.v + 2.0 * a.d * b.d + a.v * b.dd};
}
inline Smooth operator*(double c, const Smooth& a) { return {c * a.v, c * a.d, c * a.dd}; }
inline Smooth operator+(const Smooth& a, double c) { return {a.v + c, a.d, a.dd}; }
inline Smooth operator+(double c, const Smooth& a) { return a + c; }

inline Smooth sin(const Smooth& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return {s, c * a.d, c * a.dd - s * a.d * a.d};
}
inline Smooth cos(const Smooth& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return {c, -s * a.d, -s * a.dd - c * a.d * a.d};
}

// Quintic Hermite blend on tau = (t - t0) / T, clamped to [0, 1]:
//   p(tau) = p0 H0 + v0 T H1 + p1 H3 (zero end velocity and acceleration, zero start
//   acceleration). Outside [t0, t0 + T] it is constant (p0 before, p1 after); the joins are
//   twice differentiable.
Smooth QuinticBlend(double t, double t0, double T, double p0, double v0, double p1);

// 0 -> 1 transition over [t0, t0 + T]: QuinticBlend with p0 = 0, v0 = 0, p1 = 1.
inline Smooth SmoothStep(double t, double t0, double T) { return QuinticBlend(t, t0, T, 0, 0, 1); }

}  // namespace auvdock
