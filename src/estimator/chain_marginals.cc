#include "auvdock/estimator/chain_marginals.h"

#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>
#include <ceres/crs_matrix.h>

namespace auvdock {

std::optional<std::vector<std::optional<Eigen::MatrixXd>>> ChainMarginals(
    ceres::Problem* problem, const std::vector<std::vector<double*>>& states,
    const ChainMarginalsOptions& options) {
  const int n = static_cast<int>(states.size());
  std::vector<double*> blocks;
  std::vector<int> start(n + 1, 0);     // each state's first tangent column
  for (int k = 0; k < n; ++k) {
    int size = 0;
    for (double* block : states[k]) {
      if (!problem->HasParameterBlock(block)) {
        throw std::invalid_argument("ChainMarginals: a block is not in the problem");
      }
      if (problem->IsParameterBlockConstant(block)) return std::nullopt;
      blocks.push_back(block);
      size += problem->ParameterBlockTangentSize(block);
    }
    start[k + 1] = start[k] + size;
  }
  if (static_cast<int>(blocks.size()) != problem->NumParameterBlocks()) return std::nullopt;
  std::vector<std::optional<Eigen::MatrixXd>> marginals(n);
  if (n == 0) return marginals;

  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = blocks;
  evaluate.apply_loss_function = true;
  ceres::CRSMatrix crs;
  if (!problem->Evaluate(evaluate, nullptr, nullptr, nullptr, &crs)) return std::nullopt;
  const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor, int>> J(
      crs.num_rows, crs.num_cols, static_cast<Eigen::Index>(crs.values.size()), crs.rows.data(),
      crs.cols.data(), crs.values.data());
  const Eigen::SparseMatrix<double> H = J.transpose() * J;

  // The state of every column.
  std::vector<int> state_of(start[n]);
  for (int k = 0; k < n; ++k) {
    for (int c = start[k]; c < start[k + 1]; ++c) state_of[c] = k;
  }
  // Jacobi scaling: the sweeps run on H~ = W H W, W = diag(H)^-1/2 (unit diagonal), so that the
  // rank test compares like with like whatever the units (metres, rad/s of a bias).
  Eigen::VectorXd w(start[n]);
  for (int c = 0; c < start[n]; ++c) {
    const double h = H.coeff(c, c);
    w(c) = h > 0.0 ? 1.0 / std::sqrt(h) : 0.0;  // 0: unobserved, caught by the rank test
  }
  std::vector<Eigen::MatrixXd> D(n), B(n > 0 ? n - 1 : 0);
  for (int k = 0; k < n; ++k) {
    const int size = start[k + 1] - start[k];
    D[k] = Eigen::MatrixXd::Zero(size, size);
    if (k + 1 < n) B[k] = Eigen::MatrixXd::Zero(size, start[k + 2] - start[k + 1]);
  }
  std::vector<bool> joined(n > 0 ? n - 1 : 0, false);  // some factor links k and k + 1
  for (int c = 0; c < H.outerSize(); ++c) {
    const int kc = state_of[c];
    for (Eigen::SparseMatrix<double>::InnerIterator it(H, c); it; ++it) {
      const int r = static_cast<int>(it.row());
      const int kr = state_of[r];
      const double scaled = w(r) * it.value() * w(c);
      if (kr == kc) {
        D[kc](r - start[kc], c - start[kc]) = scaled;
      } else if (kc == kr + 1) {
        B[kr](r - start[kr], c - start[kc]) = scaled;
        joined[kr] = true;
      } else if (std::abs(kr - kc) > 1) {
        return std::nullopt;  // not a chain
      }
    }
  }

  // Forward: S_k and its inverse; a rank-deficient S_k marks its segment.
  std::vector<Eigen::MatrixXd> S_inv(n);
  std::vector<int> segment(n, 0);
  std::vector<bool> segment_ok(1, true);
  for (int k = 0; k < n; ++k) {
    Eigen::MatrixXd S = D[k];
    if (k > 0 && joined[k - 1]) {
      segment[k] = segment[k - 1];
      S -= B[k - 1].transpose() * S_inv[k - 1] * B[k - 1];
    } else if (k > 0) {
      segment[k] = segment[k - 1] + 1;
      segment_ok.push_back(true);
    }
    S = 0.5 * (S + S.transpose()).eval();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(S);
    const Eigen::VectorXd& values = eig.eigenvalues();
    if (eig.info() != Eigen::Success || !(values.minCoeff() > options.min_eigenvalue)) {
      segment_ok[segment[k]] = false;
      S_inv[k] = Eigen::MatrixXd::Zero(S.rows(), S.cols());  // keeps the sweep finite
      continue;
    }
    S_inv[k] = eig.eigenvectors() * values.cwiseInverse().asDiagonal() *
               eig.eigenvectors().transpose();
  }
  // Backward: the marginals.
  Eigen::MatrixXd next;
  for (int k = n - 1; k >= 0; --k) {
    Eigen::MatrixXd sigma = S_inv[k];
    if (k + 1 < n && joined[k]) {
      const Eigen::MatrixXd G = S_inv[k] * B[k];
      sigma += G * next * G.transpose();
    }
    sigma = 0.5 * (sigma + sigma.transpose()).eval();
    next = sigma;
    if (!segment_ok[segment[k]]) continue;
    // Back from the scaled coordinates: Sigma = W Sigma~ W.
    const Eigen::VectorXd wk = w.segment(start[k], start[k + 1] - start[k]);
    const Eigen::MatrixXd unscaled = wk.asDiagonal() * sigma * wk.asDiagonal();
    if (unscaled.allFinite()) marginals[k] = unscaled;
  }
  return marginals;
}

}  // namespace auvdock
