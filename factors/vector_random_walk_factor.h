// A 3-vector that drifts slowly, as an isotropic random walk between two neighbouring states i
// and j, and its prior at the first state: the DVL's bias b_S (factors/dvl_factor.h), or any
// other three-number nuisance state that must keep the estimator's chain structure (each factor
// on one state or two neighbours: estimator/chain_linearization.h). The one-number twin is
// factors/scalar_random_walk_factor.h.
//
//   between:  r = (x_j - x_i) / (q sqrt(dt)),   dt = t_j - t_i > 0 (s), q the walk's density
//             per axis (units of x per sqrt(s)): x_j - x_i ~ N(0, q^2 dt I3);
//   prior:    r = (x - x0) / sigma0 (per axis).
// Jacobians: automatic differentiation (both linear).
#pragma once

#include <cmath>
#include <stdexcept>

#include <ceres/autodiff_cost_function.h>
#include <Eigen/Core>

namespace auvdock {

inline constexpr int kVectorWalkSize = 3;

class VectorRandomWalkFactor {
 public:
  // Throws std::invalid_argument unless q > 0 and dt > 0, both finite.
  VectorRandomWalkFactor(double density_per_sqrt_s, double dt_s)
      : sigma_(density_per_sqrt_s * std::sqrt(dt_s)) {
    if (!(density_per_sqrt_s > 0.0) || !std::isfinite(density_per_sqrt_s) || !(dt_s > 0.0) ||
        !std::isfinite(dt_s)) {
      throw std::invalid_argument("VectorRandomWalkFactor: the density and dt must be > 0");
    }
  }

  template <typename T>
  bool operator()(const T* x_i, const T* x_j, T* residual) const {
    for (int k = 0; k < kVectorWalkSize; ++k) residual[k] = (x_j[k] - x_i[k]) / T(sigma_);
    return true;
  }

  double sigma() const { return sigma_; }

  static ceres::CostFunction* Create(double density_per_sqrt_s, double dt_s) {
    return new ceres::AutoDiffCostFunction<VectorRandomWalkFactor, kVectorWalkSize, kVectorWalkSize,
                                           kVectorWalkSize>(
        new VectorRandomWalkFactor(density_per_sqrt_s, dt_s));
  }

 private:
  double sigma_;
};

class VectorPriorFactor {
 public:
  // Throws std::invalid_argument for a non-finite mean or sigma <= 0.
  VectorPriorFactor(const Eigen::Vector3d& mean, double sigma) : mean_(mean), sigma_(sigma) {
    if (!mean_.allFinite() || !(sigma_ > 0.0) || !std::isfinite(sigma_)) {
      throw std::invalid_argument("VectorPriorFactor: the mean must be finite and sigma > 0");
    }
  }

  template <typename T>
  bool operator()(const T* x, T* residual) const {
    for (int k = 0; k < kVectorWalkSize; ++k) residual[k] = (x[k] - T(mean_[k])) / T(sigma_);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& mean, double sigma) {
    return new ceres::AutoDiffCostFunction<VectorPriorFactor, kVectorWalkSize, kVectorWalkSize>(
        new VectorPriorFactor(mean, sigma));
  }

 private:
  Eigen::Vector3d mean_;
  double sigma_;
};

}  // namespace auvdock
