#include "auvdock/estimator/chain_marginals.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include <Eigen/Cholesky>

#include "auvdock/estimator/chain_linearization.h"

namespace auvdock {
namespace {

// The Jacobi-scaled information of a chain, W H W with W = diag(H)^-1/2, in blocks: D[k] state k
// with itself, B[k] state k with state k + 1 (joined[k]: some factor links them).
struct ScaledChain {
  std::vector<int> start;  // each state's first tangent column; start[n] = all columns
  Eigen::VectorXd w;       // the scaling's diagonal; 0 for a coordinate without information
  std::vector<Eigen::MatrixXd> D, B;
  std::vector<bool> joined;
};

// nullopt when the problem is not a chain of these states or cannot be evaluated.
std::optional<ScaledChain> AssembleScaledChain(ceres::Problem* problem,
                                               const std::vector<std::vector<double*>>& states) {
  const int n = static_cast<int>(states.size());
  const std::optional<ChainLayout> layout = MakeChainLayout(*problem, states);
  if (!layout) return std::nullopt;
  ScaledChain chain;
  chain.start = layout->start;
  if (n == 0) return chain;
  std::optional<ChainLinearization> lin = LinearizeChain(*problem, *layout);
  if (!lin) return std::nullopt;
  chain.D = std::move(lin->D);
  chain.B = std::move(lin->B);
  chain.joined = std::move(lin->joined);
  const int columns = chain.start[n];
  // Jacobi scaling: the sweeps run on W H W (unit diagonal), so that the rank test compares like
  // with like whatever the units (metres, rad/s of a bias).
  chain.w.resize(columns);
  for (int k = 0; k < n; ++k) {
    for (int i = 0; i < chain.D[k].rows(); ++i) {
      const double h = chain.D[k](i, i);
      chain.w(chain.start[k] + i) = h > 0.0 ? 1.0 / std::sqrt(h) : 0.0;  // 0: caught below
    }
  }
  for (int k = 0; k < n; ++k) {
    const int size = chain.start[k + 1] - chain.start[k];
    const Eigen::VectorXd wk = chain.w.segment(chain.start[k], size);
    chain.D[k] = wk.asDiagonal() * chain.D[k] * wk.asDiagonal();
    if (k + 1 < n) {
      const Eigen::VectorXd wn =
          chain.w.segment(chain.start[k + 1], chain.start[k + 2] - chain.start[k + 1]);
      chain.B[k] = wk.asDiagonal() * chain.B[k] * wn.asDiagonal();
    }
  }
  return chain;
}

// The forward sweep: G_k = S_k^-1 B_k for every joined state, S_k^-1 for every state (or the
// last only: all_inverses false), each state's segment (states joined by factors) and whether
// that segment is of full rank. A rank-deficient S_k leaves G_k and S_k^-1 zero (which keeps
// the sweep finite).
struct ForwardSweep {
  std::vector<Eigen::MatrixXd> S_inv, G;
  std::vector<int> segment;
  std::vector<bool> segment_ok;
};

ForwardSweep SweepForward(const ScaledChain& chain, const ChainMarginalsOptions& options,
                          bool all_inverses) {
  const int n = static_cast<int>(chain.D.size());
  ForwardSweep sweep;
  sweep.S_inv.resize(n);
  sweep.G.resize(n);
  sweep.segment.assign(n, 0);
  sweep.segment_ok.assign(1, true);
  for (int k = 0; k < n; ++k) {
    Eigen::MatrixXd S = chain.D[k];
    if (k > 0 && chain.joined[k - 1]) {
      sweep.segment[k] = sweep.segment[k - 1];
      S.noalias() -= chain.B[k - 1].transpose() * sweep.G[k - 1];
    } else if (k > 0) {
      sweep.segment[k] = sweep.segment[k - 1] + 1;
      sweep.segment_ok.push_back(true);
    }
    S = 0.5 * (S + S.transpose()).eval();
    const bool joined_next = k + 1 < n && chain.joined[k];
    const bool inverse = all_inverses || k + 1 == n;
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(S);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive() ||
        !(ldlt.vectorD().minCoeff() > options.min_pivot)) {
      sweep.segment_ok[sweep.segment[k]] = false;
      if (inverse) sweep.S_inv[k] = Eigen::MatrixXd::Zero(S.rows(), S.cols());
      if (joined_next) sweep.G[k] = Eigen::MatrixXd::Zero(chain.B[k].rows(), chain.B[k].cols());
      continue;
    }
    if (inverse) sweep.S_inv[k] = ldlt.solve(Eigen::MatrixXd::Identity(S.rows(), S.cols()));
    if (joined_next) sweep.G[k] = ldlt.solve(chain.B[k]);
  }
  return sweep;
}

// Back from the scaled coordinates: Sigma = W Sigma~ W; nullopt if not finite.
std::optional<Eigen::MatrixXd> Unscaled(const ScaledChain& chain, int k,
                                        const Eigen::MatrixXd& scaled) {
  const Eigen::VectorXd wk = chain.w.segment(chain.start[k], chain.start[k + 1] - chain.start[k]);
  const Eigen::MatrixXd sigma = wk.asDiagonal() * scaled * wk.asDiagonal();
  if (!sigma.allFinite()) return std::nullopt;
  return sigma;
}

}  // namespace

std::optional<std::vector<std::optional<Eigen::MatrixXd>>> ChainMarginals(
    ceres::Problem* problem, const std::vector<std::vector<double*>>& states,
    const ChainMarginalsOptions& options) {
  const std::optional<ScaledChain> chain = AssembleScaledChain(problem, states);
  if (!chain) return std::nullopt;
  const int n = static_cast<int>(states.size());
  std::vector<std::optional<Eigen::MatrixXd>> marginals(n);
  if (n == 0) return marginals;
  const ForwardSweep sweep = SweepForward(*chain, options, /*all_inverses=*/true);
  // Backward: the marginals.
  Eigen::MatrixXd next;
  for (int k = n - 1; k >= 0; --k) {
    Eigen::MatrixXd sigma = sweep.S_inv[k];
    if (k + 1 < n && chain->joined[k]) {
      const Eigen::MatrixXd& G = sweep.G[k];
      sigma += G * next * G.transpose();
    }
    sigma = 0.5 * (sigma + sigma.transpose()).eval();
    next = sigma;
    if (sweep.segment_ok[sweep.segment[k]]) marginals[k] = Unscaled(*chain, k, sigma);
  }
  return marginals;
}

std::optional<LastStateMarginal> ChainMarginalOfLast(
    ceres::Problem* problem, const std::vector<std::vector<double*>>& states,
    const ChainMarginalsOptions& options) {
  if (states.empty()) throw std::invalid_argument("ChainMarginalOfLast: no state");
  const std::optional<ScaledChain> chain = AssembleScaledChain(problem, states);
  if (!chain) return std::nullopt;
  const ForwardSweep sweep = SweepForward(*chain, options, /*all_inverses=*/false);
  const int last = static_cast<int>(states.size()) - 1;
  LastStateMarginal result;
  if (sweep.segment_ok[sweep.segment[last]]) {
    result.covariance = Unscaled(*chain, last, sweep.S_inv[last]);
  }
  return result;
}

}  // namespace auvdock
