// A scalar that drifts slowly, as a random walk between two neighbouring states i and j, and its
// prior at the first state: the offset of a pressure-depth sensor (factors/depth_offset_factor.h),
// or any other one-number nuisance state that must keep the estimator's chain structure (each
// factor on one state or two neighbours: estimator/chain_linearization.h).
//
//   between:  r = (x_j - x_i) / (q sqrt(dt)),   dt = t_j - t_i > 0 (s), q the walk's density
//             (units of x per sqrt(s)): x_j - x_i ~ N(0, q^2 dt);
//   prior:    r = (x - x0) / sigma0.
// Jacobians: automatic differentiation (both linear).
#pragma once

#include <cmath>
#include <stdexcept>

#include <ceres/autodiff_cost_function.h>

namespace auvdock {

class ScalarRandomWalkFactor {
 public:
  // Throws std::invalid_argument unless q > 0 and dt > 0, both finite.
  ScalarRandomWalkFactor(double density_per_sqrt_s, double dt_s)
      : sigma_(density_per_sqrt_s * std::sqrt(dt_s)) {
    if (!(density_per_sqrt_s > 0.0) || !std::isfinite(density_per_sqrt_s) || !(dt_s > 0.0) ||
        !std::isfinite(dt_s)) {
      throw std::invalid_argument("ScalarRandomWalkFactor: the density and dt must be > 0");
    }
  }

  template <typename T>
  bool operator()(const T* x_i, const T* x_j, T* residual) const {
    residual[0] = (x_j[0] - x_i[0]) / T(sigma_);
    return true;
  }

  double sigma() const { return sigma_; }

  static ceres::CostFunction* Create(double density_per_sqrt_s, double dt_s) {
    return new ceres::AutoDiffCostFunction<ScalarRandomWalkFactor, 1, 1, 1>(
        new ScalarRandomWalkFactor(density_per_sqrt_s, dt_s));
  }

 private:
  double sigma_;
};

class ScalarPriorFactor {
 public:
  // Throws std::invalid_argument for a non-finite mean or sigma <= 0.
  ScalarPriorFactor(double mean, double sigma) : mean_(mean), sigma_(sigma) {
    if (!std::isfinite(mean_) || !(sigma_ > 0.0) || !std::isfinite(sigma_)) {
      throw std::invalid_argument("ScalarPriorFactor: the mean must be finite and sigma > 0");
    }
  }

  template <typename T>
  bool operator()(const T* x, T* residual) const {
    residual[0] = (x[0] - T(mean_)) / T(sigma_);
    return true;
  }

  static ceres::CostFunction* Create(double mean, double sigma) {
    return new ceres::AutoDiffCostFunction<ScalarPriorFactor, 1, 1>(
        new ScalarPriorFactor(mean, sigma));
  }

 private:
  double mean_;
  double sigma_;
};

}  // namespace auvdock
