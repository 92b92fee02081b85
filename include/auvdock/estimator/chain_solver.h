// Levenberg-Marquardt for a chain-structured least-squares problem (chain_linearization.h: states
// linked only to their neighbours in time), solving each step's normal equations by the block-
// tridiagonal factorisation of their information instead of a general sparse Cholesky.
//
// Why: the sliding window's problem is a chain of ~10 states of 15 tangent coordinates (pose 6,
// velocity 3, biases 6), the batch smoother's a chain of the whole log's states. Ceres' SPARSE_NORMAL_CHOLESKY forms J^T J as a general sparse product
// and hands it to CHOLMOD, whose set-up dominates at this size (39 % of the window's update on
// 2026-12-06's profile); the chain's own factorisation costs O(n 15^3) and its blocks come
// straight from the residual blocks.
//
// Math. At x, with the linearisation g, H (chain_linearization.h: block-tridiagonal, D_k and
// B_k), each iteration solves
//   (H + lambda diag(H)) delta = -g
// (diag(H) clamped to [min_diagonal, max_diagonal], as Ceres' Levenberg-Marquardt strategy does)
// by the block LDL^T sweep
//   S_0 = D~_0,   S_k = D~_k - B_{k-1}^T S_{k-1}^-1 B_{k-1}        (D~ the damped diagonal blocks)
//   y_0 = -g_0,   y_k = -g_k - B_{k-1}^T S_{k-1}^-1 y_{k-1}
//   delta_{n-1} = S_{n-1}^-1 y_{n-1},   delta_k = S_k^-1 (y_k - B_k delta_{k+1}),
// each S_k by a Cholesky factorisation (positive definite for lambda > 0 and a non-zero diagonal).
// The step x (+) delta (each block's manifold Plus) is kept when its gain ratio
//   rho = (F(x) - F(x (+) delta)) / (-g^T delta - 1/2 delta^T H delta)
// exceeds min_relative_decrease; lambda then shrinks by max(1/3, 1 - (2 rho - 1)^3), and grows by
// a doubling factor after each refused step (Nielsen's rule, Madsen, Nielsen & Tingleff, "Methods
// for non-linear least squares problems", 2004, sec. 3.2; the rule Ceres' trust region uses).
//
// Stops (the first that holds): max_iterations steps tried; a kept step that lowered the cost by
// less than cost_change_tolerance (absolute; 0: off) or by less than function_tolerance of the
// cost; the gradient's largest coordinate at or below gradient_tolerance; a step no longer than
// parameter_tolerance (|x| + parameter_tolerance); max_time_s of wall time (0: none); lambda
// beyond max_lambda (no step lowers the cost).
//
// Units: those of the problem's tangent spaces.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <ceres/problem.h>

namespace auvdock {

struct ChainSolverOptions {
  int max_iterations = 50;
  double cost_change_tolerance = 0.0;  // absolute, per kept step; 0: off
  double function_tolerance = 1e-6;    // relative cost change
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-8;
  double max_time_s = 0.0;       // 0: no limit (deterministic)
  double initial_lambda = 1e-4;  // Ceres' initial trust region radius 1e4
  double max_lambda = 1e32;
  double min_relative_decrease = 1e-3;
  double min_diagonal = 1e-6;
  double max_diagonal = 1e32;
  // Called with (iteration, cost) at the start (iteration 0) and after every step tried, as
  // Ceres' iteration callbacks are.
  std::function<void(int, double)> progress;
};

struct ChainSolverSummary {
  bool usable = false;  // the values are finite and the cost at them could be evaluated
  int iterations = 0;   // steps tried
  int successful_steps = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  std::string termination;  // why it stopped
  bool converged = false;   // by a tolerance (not the iteration or time limit, nor a failure)
};

// Minimises the problem over the states' blocks (chain order), starting from their values; the
// blocks hold the result. nullopt, with the values untouched, when the problem is not a chain of
// these states (chain_linearization.h: a block outside them, a constant block, a factor joining
// states more than one apart): the caller uses a general solver. Throws std::invalid_argument
// for a block not in the problem or options out of range.
std::optional<ChainSolverSummary> SolveChain(ceres::Problem* problem,
                                             const std::vector<std::vector<double*>>& states,
                                             const ChainSolverOptions& options = {});

}  // namespace auvdock
