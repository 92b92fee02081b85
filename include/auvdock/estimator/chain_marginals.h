// Marginal covariances of every state of a chain: a least-squares problem whose states (each a
// group of parameter blocks, e.g. pose, velocity, biases) are linked only to their neighbours in
// time, as in the batch smoother (IMU factors between consecutive states; every vision, depth,
// DVL, USBL and prior factor on one state).
//
// Math. With the tangent-space Jacobian J of every residual block at the current values (robust
// losses applied as Ceres' corrector does; chain_linearization.h), the Gauss-Newton information
// H = J^T J of a chain is block-tridiagonal: diagonal blocks D_k (state k with itself),
// off-diagonal blocks B_k = H_{k,k+1}.
// The diagonal blocks of H^-1 follow from two sweeps (the block-tridiagonal inverse; the
// information form of a Rauch-Tung-Striebel smoother):
//   forward:   S_0 = D_0,   S_k = D_k - B_{k-1}^T S_{k-1}^-1 B_{k-1}
//   backward:  Sigma_{n-1} = S_{n-1}^-1,
//              Sigma_k = S_k^-1 + G_k Sigma_{k+1} G_k^T,   G_k = S_k^-1 B_k,
// which is O(n) in the number of states, where ceres::Covariance solves R^T R x = e_j for each
// requested column over the whole problem: O(n^2) (a 300 s log of 3000 states spent 62 % of
// `smooth`'s time there). S_k is the information of state k given the states before it only;
// Sigma_k the marginal given all of them.
//
// The sweeps run on the Jacobi-scaled information W H W, W = diag(H)^-1/2 (unit diagonal, so
// that metres and a gyro bias's rad/s compare), and the marginals are scaled back, W Sigma W.
//
// The last state's marginal needs the forward sweep alone: Sigma_{n-1} = S_{n-1}^-1 (the
// information form of a filter's update), O(n) with a small constant (the sliding window's
// newest-pose covariance, every frame).
//
// H is accumulated straight into the blocks D_k and B_k, one residual block at a time
// (chain_linearization.h), without forming J^T J as a general sparse product.
//
// Segments: B_k = 0 where no factor joins states k and k+1 (an IMU gap); the sweeps then treat
// the two parts independently. Rank deficiency: a scaled S_k whose smallest pivot (of its
// LDLT factorisation with diagonal pivoting) is at or below min_pivot (a gauge freedom, an
// unobserved direction: rounding-level on the unit diagonal), or a coordinate with no information at all, leaves its whole segment without
// covariances (nullopt for each of its states): a rank-deficient problem has no inverse to report.
//
// Units: those of the blocks' tangent spaces.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <ceres/problem.h>

namespace auvdock {

struct ChainMarginalsOptions {
  double min_pivot = 1e-12;  // of a Jacobi-scaled S_k's LDLT (see above)
};

// states: each state's parameter blocks (all in the problem, none constant), in chain order.
// Returns each state's marginal covariance (the sum of its blocks' tangent sizes square, blocks
// in the given order), nullopt for the states of a rank-deficient segment; or nullopt as a
// whole when the problem is not a chain (a factor joins states more than one apart, or a
// variable block belongs to no state) or cannot be evaluated: the caller falls back to a general
// method. Throws std::invalid_argument for a block not in the problem.
std::optional<std::vector<std::optional<Eigen::MatrixXd>>> ChainMarginals(
    ceres::Problem* problem, const std::vector<std::vector<double*>>& states,
    const ChainMarginalsOptions& options = {});

// The last state's marginal covariance only (the forward sweep; see above): equal to
// ChainMarginals(...)->back() to rounding. covariance is nullopt when the last state's segment
// is rank-deficient; the whole result nullopt when the problem is not a chain (as above). Throws
// std::invalid_argument for no state or a block not in the problem.
struct LastStateMarginal {
  std::optional<Eigen::MatrixXd> covariance;
};
std::optional<LastStateMarginal> ChainMarginalOfLast(
    ceres::Problem* problem, const std::vector<std::vector<double*>>& states,
    const ChainMarginalsOptions& options = {});

}  // namespace auvdock
