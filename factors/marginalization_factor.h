// The prior left behind when states are marginalized out of the sliding window: a linear(ised)
// Gaussian on the kept parameter blocks, expressed in their tangent spaces about the point where
// the marginalization happened (first-estimate Jacobians, as in OKVIS / VINS-Mono).
//
// With dx the stacked tangent differences of the kept blocks from their linearisation point x0,
//   dx = [x_1 [-] x0_1; ...; x_n [-] x0_n],      ([-] = Minus: p - p0 and Log(q q0^-1) for a
//                                                  pose block, plain subtraction otherwise)
//   residual r(x) = r0 + J dx,   cost 1/2 |r|^2,
// where J (m x N, N = sum of the tangent sizes) and r0 come from the Schur complement of the
// marginalized blocks (estimator/marginalization.h): J^T J = H*, J^T r0 = b*.
//
// The Jacobian returned to Ceres is with respect to each block's ambient parameters:
//   d r / d x_i = J_i * d(x_i [-] x0_i) / d x_i,
// exact for the pose's rotation (the 3 x 4 derivative of Log(q q0^-1) by automatic
// differentiation) and the identity for Euclidean blocks; Ceres then applies the block's
// manifold (PlusJacobian), which makes it J_i at x = x0.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ceres/cost_function.h>
#include <ceres/jet.h>

#include "factors/pose_manifold.h"

namespace auvdock {

enum class MarginalBlockKind { kEuclidean, kPose };

struct LinearizedPrior {
  struct Block {
    double* parameters = nullptr;   // the kept block (the estimator's memory)
    MarginalBlockKind kind = MarginalBlockKind::kEuclidean;
    Eigen::VectorXd linearization_point;  // x0, ambient size
    int tangent_size() const {
      return kind == MarginalBlockKind::kPose ? kPoseTangentSize
                                              : static_cast<int>(linearization_point.size());
    }
  };
  std::vector<Block> blocks;
  Eigen::MatrixXd sqrt_information;  // J: rank x sum of tangent sizes
  Eigen::VectorXd residual;          // r0: rank

  int tangent_size() const {
    int n = 0;
    for (const Block& b : blocks) n += b.tangent_size();
    return n;
  }
};

class MarginalizationFactor final : public ceres::CostFunction {
 public:
  explicit MarginalizationFactor(LinearizedPrior prior) : prior_(std::move(prior)) {
    set_num_residuals(static_cast<int>(prior_.residual.size()));
    for (const LinearizedPrior::Block& b : prior_.blocks) {
      mutable_parameter_block_sizes()->push_back(static_cast<int>(b.linearization_point.size()));
    }
  }

  // The parameter pointers to pass to Problem::AddResidualBlock, in order.
  std::vector<double*> parameter_blocks() const {
    std::vector<double*> blocks;
    for (const LinearizedPrior::Block& b : prior_.blocks) blocks.push_back(b.parameters);
    return blocks;
  }
  const LinearizedPrior& prior() const { return prior_; }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int m = num_residuals();
    Eigen::VectorXd dx(prior_.tangent_size());
    int offset = 0;
    for (size_t i = 0; i < prior_.blocks.size(); ++i) {
      const LinearizedPrior::Block& b = prior_.blocks[i];
      const int n = b.tangent_size();
      if (b.kind == MarginalBlockKind::kPose) {
        dx.segment<kPoseTangentSize>(offset) = PoseMinus<double>(parameters[i], b);
      } else {
        dx.segment(offset, n) =
            Eigen::Map<const Eigen::VectorXd>(parameters[i], n) - b.linearization_point;
      }
      offset += n;
    }
    Eigen::Map<Eigen::VectorXd>(residuals, m) = prior_.residual + prior_.sqrt_information * dx;
    if (jacobians == nullptr) return true;

    offset = 0;
    for (size_t i = 0; i < prior_.blocks.size(); ++i) {
      const LinearizedPrior::Block& b = prior_.blocks[i];
      const int n = b.tangent_size();
      if (jacobians[i] != nullptr) {
        const int ambient = static_cast<int>(b.linearization_point.size());
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(
            jacobians[i], m, ambient);
        const auto J_r_dx = prior_.sqrt_information.middleCols(offset, n);
        if (b.kind == MarginalBlockKind::kPose) {
          J = J_r_dx * PoseMinusJacobian(parameters[i], b);
        } else {
          J = J_r_dx;
        }
      }
      offset += n;
    }
    return true;
  }

 private:
  template <typename T>
  static Eigen::Matrix<T, 6, 1> PoseMinus(const T* x, const LinearizedPrior::Block& b) {
    const Eigen::Quaternion<T> q(x[6], x[3], x[4], x[5]);
    const Eigen::Quaterniond q0(b.linearization_point[6], b.linearization_point[3],
                                b.linearization_point[4], b.linearization_point[5]);
    Eigen::Matrix<T, 6, 1> d;
    for (int k = 0; k < 3; ++k) d[k] = x[k] - T(b.linearization_point[k]);
    d.template tail<3>() = QuaternionLog<T>(q * q0.conjugate().template cast<T>());
    return d;
  }

  // d(x [-] x0) / d x for a pose block (6 x 7), by forward-mode automatic differentiation.
  static Eigen::Matrix<double, 6, 7> PoseMinusJacobian(const double* x,
                                                       const LinearizedPrior::Block& b) {
    using Jet = ceres::Jet<double, kPoseSize>;
    Jet xj[kPoseSize];
    for (int k = 0; k < kPoseSize; ++k) xj[k] = Jet(x[k], k);
    const Eigen::Matrix<Jet, 6, 1> d = PoseMinus<Jet>(xj, b);
    Eigen::Matrix<double, 6, 7> J;
    for (int r = 0; r < 6; ++r) J.row(r) = d[r].v.transpose();
    return J;
  }

  LinearizedPrior prior_;
};

}  // namespace auvdock
