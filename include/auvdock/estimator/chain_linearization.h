// The Gauss-Newton linearisation of a chain-structured least-squares problem, evaluated straight
// from its residual blocks: a problem whose states (each a group of parameter blocks, e.g. pose,
// velocity, biases) are linked only to their neighbours in time (IMU factors between consecutive
// states; every vision, depth, DVL, acoustic and prior factor on one state). The sliding window
// and the batch smoother are such chains.
//
// Math. The cost is F(x) = 1/2 sum_i rho_i(|r_i(x)|^2) (rho_i the block's robust loss, the
// identity without one), as Ceres defines it. Each residual block's Jacobian is taken in the
// tangent spaces of its blocks, J = J_ambient * dPlus(x, delta)/ddelta at delta = 0, and a robust
// loss enters as Ceres' corrector does (Triggs et al., "Bundle adjustment - a modern synthesis",
// 2000, sec. 4.3): with s = |r|^2 and rho', rho'' at s,
//   alpha = 1 - sqrt(1 + 2 s rho'' / rho')   (0 when rho'' <= 0 or s = 0),
//   r~ = sqrt(rho') / (1 - alpha) r,   J~ = sqrt(rho') (I - alpha r r^T / s) J,
// so that J~^T r~ = rho' J^T r is the true gradient and J~^T J~ a Gauss-Newton approximation of
// the robust cost's Hessian that keeps its curvature along r. Then
//   g = sum J~^T r~ (the gradient, per state),
//   H = sum J~^T J~, block-tridiagonal: D_k (state k with itself), B_k = H_{k,k+1}.
// Each residual block touches one state or two neighbours, so its J~^T J~ is added straight into
// D and B block by block, without a general sparse product.
//
// Layout: each state's tangent coordinates are its blocks' tangent coordinates in the order
// given; a block's manifold is the one the problem holds for it.
//
// Units: those of the blocks' tangent spaces and of the residuals.
#pragma once

#include <optional>
#include <unordered_map>
#include <vector>

#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <Eigen/Core>

namespace auvdock {

// Where each parameter block lives in the chain.
struct ChainLayout {
  struct Block {
    int state = 0;
    int offset = 0;                             // first tangent coordinate within its state
    int tangent = 0;                            // tangent size
    int ambient = 0;                            // stored size
    const ceres::Manifold* manifold = nullptr;  // nullptr: Euclidean
  };
  std::vector<int> start;  // each state's first tangent coordinate overall; start[n] = all
  std::unordered_map<const double*, Block> blocks;
  int num_states() const { return static_cast<int>(start.size()) - 1; }
  int state_size(int k) const { return start[k + 1] - start[k]; }
};

// states: each state's parameter blocks, in chain order. nullopt when the problem holds a
// parameter block outside the states or a state's block is held constant (not a chain this
// module handles). Throws std::invalid_argument for a block not in the problem.
std::optional<ChainLayout> MakeChainLayout(const ceres::Problem& problem,
                                           const std::vector<std::vector<double*>>& states);

struct ChainLinearization {
  double cost = 0.0;
  Eigen::VectorXd gradient;           // J~^T r~, all tangent coordinates
  std::vector<Eigen::MatrixXd> D, B;  // D[k]: full symmetric; B[k] = H_{k,k+1}
  std::vector<bool> joined;           // joined[k]: some factor links states k and k + 1
};

// The linearisation at the problem's current values. nullopt when a residual block cannot be
// evaluated, is not finite, or joins states more than one apart (not a chain). The problem's
// structure is read anew at each call (caching it per solve measured slower: its set-up cost
// more than the queries it saved at 2-6 linearisations a solve).
std::optional<ChainLinearization> LinearizeChain(const ceres::Problem& problem,
                                                 const ChainLayout& layout);

// The cost F(x) alone at the current values; nullopt when a block cannot be evaluated or is not
// finite.
std::optional<double> ChainCost(const ceres::Problem& problem);

}  // namespace auvdock
