#include "auvdock/estimator/marginalization.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_set>

#include <Eigen/Eigenvalues>
#include <ceres/crs_matrix.h>

namespace auvdock {
namespace {

int TangentSizeOf(const ceres::Problem& problem, double* block) {
  return problem.ParameterBlockTangentSize(block);
}

// The Jacobi scaling of a symmetric positive semi-definite matrix: w_i = 1 / sqrt(A_ii) (0 where
// A_ii is not positive), so that W A W has a unit diagonal.
Eigen::VectorXd JacobiScaling(const Eigen::MatrixXd& A) {
  Eigen::VectorXd w(A.rows());
  for (Eigen::Index i = 0; i < A.rows(); ++i) w[i] = A(i, i) > 0.0 ? 1.0 / std::sqrt(A(i, i)) : 0.0;
  return w;
}

// Moore-Penrose inverse of a symmetric positive semi-definite matrix, its rank decided on the
// Jacobi-scaled matrix (JacobiScaling): A^+ = W (W A W)^+ W.
Eigen::MatrixXd PseudoInverse(const Eigen::MatrixXd& A, double relative_floor) {
  if (A.rows() == 0) return A;
  const Eigen::VectorXd w = JacobiScaling(A);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(w.asDiagonal() * A * w.asDiagonal());
  const Eigen::VectorXd& s = eig.eigenvalues();
  const double floor = relative_floor * std::max(0.0, s.maxCoeff());
  Eigen::VectorXd s_inv(s.size());
  for (int i = 0; i < s.size(); ++i) s_inv[i] = s[i] > floor && s[i] > 0.0 ? 1.0 / s[i] : 0.0;
  return w.asDiagonal() *
         (eig.eigenvectors() * s_inv.asDiagonal() * eig.eigenvectors().transpose()) *
         w.asDiagonal();
}

}  // namespace

LinearizedPrior MarginalizeOut(ceres::Problem* problem, const std::vector<double*>& blocks,
                               const MarginalizationOptions& options) {
  const std::unordered_set<double*> marginalized(blocks.begin(), blocks.end());
  for (double* block : blocks) {
    if (!problem->HasParameterBlock(block)) {
      throw std::invalid_argument("MarginalizeOut: a block to marginalize is not in the problem");
    }
  }
  // Residual blocks touching the marginalized blocks, and the kept blocks they connect to, in a
  // deterministic order (first appearance).
  std::vector<ceres::ResidualBlockId> residual_blocks;
  std::unordered_set<ceres::ResidualBlockId> seen_residuals;
  std::vector<double*> kept;
  std::unordered_set<double*> seen_kept;
  for (double* block : blocks) {
    std::vector<ceres::ResidualBlockId> touching;
    problem->GetResidualBlocksForParameterBlock(block, &touching);
    for (ceres::ResidualBlockId id : touching) {
      if (!seen_residuals.insert(id).second) continue;
      residual_blocks.push_back(id);
      std::vector<double*> params;
      problem->GetParameterBlocksForResidualBlock(id, &params);
      for (double* p : params) {
        if (marginalized.count(p) == 0 && seen_kept.insert(p).second) kept.push_back(p);
      }
    }
  }

  LinearizedPrior prior;
  for (double* p : kept) {
    LinearizedPrior::Block b;
    b.parameters = p;
    const ceres::Manifold* manifold = problem->GetManifold(p);
    if (manifold == nullptr) {
      b.kind = MarginalBlockKind::kEuclidean;
    } else if (dynamic_cast<const PoseManifold*>(manifold) != nullptr) {
      b.kind = MarginalBlockKind::kPose;
    } else {
      throw std::invalid_argument("MarginalizeOut: a kept block has an unsupported manifold");
    }
    const int size = problem->ParameterBlockSize(p);
    b.linearization_point = Eigen::Map<const Eigen::VectorXd>(p, size);
    prior.blocks.push_back(std::move(b));
  }

  if (!residual_blocks.empty() && !kept.empty()) {
    ceres::Problem::EvaluateOptions evaluate;
    evaluate.parameter_blocks = blocks;
    evaluate.parameter_blocks.insert(evaluate.parameter_blocks.end(), kept.begin(), kept.end());
    evaluate.residual_blocks = residual_blocks;
    evaluate.apply_loss_function = true;
    std::vector<double> residuals;
    ceres::CRSMatrix crs;
    problem->Evaluate(evaluate, nullptr, &residuals, nullptr, &crs);

    int m = 0;
    for (double* block : blocks) m += TangentSizeOf(*problem, block);
    const int n = crs.num_cols;
    const int k = n - m;
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, n);
    for (int row = 0; row < crs.num_rows; ++row) {
      for (int idx = crs.rows[row]; idx < crs.rows[row + 1]; ++idx) {
        J(row, crs.cols[idx]) = crs.values[idx];
      }
    }
    const Eigen::Map<const Eigen::VectorXd> r(residuals.data(),
                                              static_cast<Eigen::Index>(residuals.size()));
    const Eigen::MatrixXd H = J.transpose() * J;
    const Eigen::VectorXd b = J.transpose() * r;
    const Eigen::MatrixXd H_mm_inv = PseudoInverse(H.topLeftCorner(m, m),
                                                   options.relative_eigen_floor);
    const Eigen::MatrixXd H_km = H.bottomLeftCorner(k, m);
    Eigen::MatrixXd H_star = H.bottomRightCorner(k, k) - H_km * H_mm_inv * H_km.transpose();
    H_star = 0.5 * (H_star + H_star.transpose()).eval();
    const Eigen::VectorXd b_star = b.tail(k) - H_km * H_mm_inv * b.head(m);

    // The rank is decided on the Jacobi-scaled H* (unit diagonal), not on H* itself: its
    // coordinates are in different units, and a navigation-grade IMU's bias walk gives the
    // biases 1e11-1e15 of information where a prior gives the position 1-100; unscaled, the
    // position's directions fell under the floor and were dropped as unobserved (A-KIT without
    // fixes: the position left free, hundreds of metres off within a minute).
    // With H_s = W H* W = V S V^T: J* = S^1/2 V^T W^-1, r0 = S^-1/2 V^T W b*.
    const Eigen::VectorXd w = JacobiScaling(H_star);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(w.asDiagonal() * H_star *
                                                             w.asDiagonal());
    const Eigen::VectorXd& s = eig.eigenvalues();
    const double floor = options.relative_eigen_floor * std::max(0.0, s.maxCoeff());
    std::vector<int> kept_directions;
    for (int i = 0; i < s.size(); ++i) {
      if (s[i] > floor && s[i] > 0.0) kept_directions.push_back(i);
    }
    const int rank = static_cast<int>(kept_directions.size());
    prior.sqrt_information.resize(rank, k);
    prior.residual.resize(rank);
    const Eigen::VectorXd w_inv = w.unaryExpr([](double x) { return x > 0.0 ? 1.0 / x : 0.0; });
    const Eigen::VectorXd scaled_b = w.asDiagonal() * b_star;
    for (int i = 0; i < rank; ++i) {
      const int d = kept_directions[i];
      const double sqrt_s = std::sqrt(s[d]);
      prior.sqrt_information.row(i) =
          sqrt_s * (eig.eigenvectors().col(d).transpose() * w_inv.asDiagonal());
      prior.residual[i] = eig.eigenvectors().col(d).dot(scaled_b) / sqrt_s;
    }
  } else {
    prior.blocks.clear();
  }

  for (ceres::ResidualBlockId id : residual_blocks) problem->RemoveResidualBlock(id);
  for (double* block : blocks) problem->RemoveParameterBlock(block);
  if (prior.residual.size() == 0) prior.blocks.clear();
  return prior;
}

void PriorInformation(const LinearizedPrior& prior, Eigen::MatrixXd* H, Eigen::VectorXd* b) {
  *H = prior.sqrt_information.transpose() * prior.sqrt_information;
  *b = prior.sqrt_information.transpose() * prior.residual;
}

}  // namespace auvdock
