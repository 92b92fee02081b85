#include "auvdock/estimator/chain_solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <Eigen/Cholesky>

#include "auvdock/estimator/chain_linearization.h"

namespace auvdock {
namespace {

// One parameter block of the chain, in the order of its tangent coordinates.
struct ChainBlock {
  double* values = nullptr;
  int ambient = 0;
  int tangent = 0;
  int column = 0;  // first tangent coordinate overall
  const ceres::Manifold* manifold = nullptr;
};

// (H + lambda diag(H)) delta = -g by the block-tridiagonal sweep (header), written as the block
// Cholesky factorisation H~ = L L^T: L_kk = chol(S_k), L_{k+1,k} = W_{k+1}^T with
// W_{k+1} = L_kk^-1 B_k, so S_{k+1} = D~_{k+1} - W_{k+1}^T W_{k+1}; forward z_k = L_kk^-1 (-g_k -
// W_k^T z_{k-1}), backward delta_k = L_kk^-T (z_k - W_{k+1} delta_{k+1}). One triangular solve
// with a block per state. False when a pivot block is not positive definite.
bool SolveDampedChain(const ChainLinearization& lin, const std::vector<int>& start, double lambda,
                      const ChainSolverOptions& options, Eigen::VectorXd* delta) {
  const int n = static_cast<int>(lin.D.size());
  std::vector<Eigen::MatrixXd> L(n), W(n);  // W[k] = L_{k-1,k-1}^-1 B_{k-1} (W[0] unused)
  std::vector<bool> joined(n, false);
  std::vector<Eigen::VectorXd> z(n);
  for (int k = 0; k < n; ++k) {
    Eigen::MatrixXd& S = L[k];
    S = lin.D[k];
    S.diagonal() +=
        lambda * lin.D[k].diagonal().cwiseMax(options.min_diagonal).cwiseMin(options.max_diagonal);
    z[k] = -lin.gradient.segment(start[k], start[k + 1] - start[k]);
    joined[k] = k > 0 && lin.joined[k - 1];
    if (joined[k]) {
      W[k] = L[k - 1].triangularView<Eigen::Lower>().solve(lin.B[k - 1]);
      S.selfadjointView<Eigen::Lower>().rankUpdate(W[k].transpose(), -1.0);
      z[k].noalias() -= W[k].transpose() * z[k - 1];
    }
    Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(S);  // in place: S holds L_kk below its diagonal
    if (llt.info() != Eigen::Success) return false;
    S.triangularView<Eigen::Lower>().solveInPlace(z[k]);
  }
  delta->resize(start[n]);
  Eigen::VectorXd next;
  for (int k = n - 1; k >= 0; --k) {
    Eigen::VectorXd rhs = z[k];
    if (k + 1 < n && joined[k + 1]) rhs.noalias() -= W[k + 1] * next;
    L[k].triangularView<Eigen::Lower>().transpose().solveInPlace(rhs);
    next = rhs;
    delta->segment(start[k], next.size()) = next;
  }
  return delta->allFinite();
}

// delta^T H delta with H in its blocks.
double QuadraticForm(const ChainLinearization& lin, const std::vector<int>& start,
                     const Eigen::VectorXd& delta) {
  const int n = static_cast<int>(lin.D.size());
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    const auto d_k = delta.segment(start[k], start[k + 1] - start[k]);
    sum += d_k.dot(lin.D[k] * d_k);
    if (k + 1 < n && lin.joined[k]) {
      sum += 2.0 * d_k.dot(lin.B[k] * delta.segment(start[k + 1], start[k + 2] - start[k + 1]));
    }
  }
  return sum;
}

}  // namespace

std::optional<ChainSolverSummary> SolveChain(ceres::Problem* problem,
                                             const std::vector<std::vector<double*>>& states,
                                             const ChainSolverOptions& options) {
  if (options.max_iterations < 0 || !(options.cost_change_tolerance >= 0.0) ||
      !(options.function_tolerance >= 0.0) || !(options.gradient_tolerance >= 0.0) ||
      !(options.parameter_tolerance >= 0.0) || !(options.max_time_s >= 0.0) ||
      !(options.initial_lambda > 0.0) || !(options.max_lambda >= options.initial_lambda) ||
      !(options.min_relative_decrease >= 0.0) || !(options.min_diagonal > 0.0) ||
      !(options.max_diagonal >= options.min_diagonal)) {
    throw std::invalid_argument("SolveChain: options out of range");
  }
  using Clock = std::chrono::steady_clock;
  const Clock::time_point started = Clock::now();
  const std::optional<ChainLayout> layout = MakeChainLayout(*problem, states);
  if (!layout) return std::nullopt;
  std::optional<ChainLinearization> lin = LinearizeChain(*problem, *layout);
  if (!lin) return std::nullopt;  // not a chain, or not evaluable: the general solver says which

  std::vector<ChainBlock> blocks;
  int ambient_size = 0;
  for (const auto& state : states) {
    for (double* values : state) {
      const ChainLayout::Block& info = layout->blocks.at(values);
      blocks.push_back({values, info.ambient, info.tangent, layout->start[info.state] + info.offset,
                        info.manifold});
      ambient_size += info.ambient;
    }
  }
  std::vector<double> saved(ambient_size);
  auto save = [&]() {
    int at = 0;
    for (const ChainBlock& b : blocks) {
      std::copy(b.values, b.values + b.ambient, saved.begin() + at);
      at += b.ambient;
    }
  };
  auto restore = [&]() {
    int at = 0;
    for (const ChainBlock& b : blocks) {
      std::copy(saved.begin() + at, saved.begin() + at + b.ambient, b.values);
      at += b.ambient;
    }
  };
  // x (+) delta into the blocks (saved holds x); false when a manifold refuses the step.
  auto step = [&](const Eigen::VectorXd& delta) {
    int at = 0;
    for (const ChainBlock& b : blocks) {
      const double* x = saved.data() + at;
      if (b.manifold == nullptr) {
        for (int i = 0; i < b.ambient; ++i) b.values[i] = x[i] + delta(b.column + i);
      } else if (!b.manifold->Plus(x, delta.data() + b.column, b.values)) {
        return false;
      }
      at += b.ambient;
    }
    return true;
  };

  ChainSolverSummary summary;
  summary.initial_cost = lin->cost;
  double cost = lin->cost;
  double lambda = options.initial_lambda;
  double growth = 2.0;
  Eigen::VectorXd delta;
  summary.termination = "maximum number of iterations";
  if (options.progress) options.progress(0, cost);
  while (true) {
    if (lin->gradient.size() == 0 ||
        lin->gradient.cwiseAbs().maxCoeff() <= options.gradient_tolerance) {
      summary.termination = "gradient tolerance";
      break;
    }
    if (summary.iterations >= options.max_iterations) break;
    if (options.max_time_s > 0.0 &&
        std::chrono::duration<double>(Clock::now() - started).count() > options.max_time_s) {
      summary.termination = "time limit";
      break;
    }
    ++summary.iterations;
    bool kept = false;
    double decrease = 0.0;
    if (SolveDampedChain(*lin, layout->start, lambda, options, &delta)) {
      save();
      double x_norm2 = 0.0;
      for (double v : saved) x_norm2 += v * v;
      if (delta.norm() <=
          options.parameter_tolerance * (std::sqrt(x_norm2) + options.parameter_tolerance)) {
        summary.termination = "parameter tolerance";
        break;
      }
      const double model_decrease =
          -lin->gradient.dot(delta) - 0.5 * QuadraticForm(*lin, layout->start, delta);
      std::optional<double> new_cost;
      if (model_decrease > 0.0 && step(delta)) new_cost = ChainCost(*problem);
      if (new_cost) {
        decrease = cost - *new_cost;
        const double ratio = decrease / model_decrease;
        kept = ratio > options.min_relative_decrease;
        if (kept) {
          lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * ratio - 1.0, 3));
          growth = 2.0;
        }
      }
      if (!kept) restore();
    }
    if (options.progress) options.progress(summary.iterations, kept ? cost - decrease : cost);
    if (!kept) {
      lambda *= growth;
      growth *= 2.0;
      if (lambda > options.max_lambda) {
        summary.termination = "no step lowers the cost";
        break;
      }
      continue;
    }
    ++summary.successful_steps;
    const double previous = cost;
    cost -= decrease;
    if ((options.cost_change_tolerance > 0.0 && decrease < options.cost_change_tolerance) ||
        decrease <= options.function_tolerance * previous) {
      summary.termination = "cost change below tolerance";
      break;
    }
    lin = LinearizeChain(*problem, *layout);
    if (!lin) {
      summary.termination = "the Jacobian could not be evaluated";
      break;
    }
    cost = lin->cost;
  }
  summary.final_cost = cost;
  summary.usable = std::isfinite(cost);
  summary.converged = summary.termination == "gradient tolerance" ||
                      summary.termination == "parameter tolerance" ||
                      summary.termination == "cost change below tolerance";
  for (const ChainBlock& b : blocks) {
    if (!std::all_of(b.values, b.values + b.ambient, [](double v) { return std::isfinite(v); })) {
      summary.usable = false;
    }
  }
  return summary;
}

}  // namespace auvdock
