// Marginalization of parameter blocks out of a Ceres problem by Schur complement, in the tangent
// space: what the sliding window does with its oldest state (Leutenegger et al. 2015, OKVIS;
// Qin et al. 2018, VINS-Mono).
//
// Every residual block that touches a marginalized block m is linearised at the current values
// (Problem::Evaluate: tangent-space Jacobians, robust losses applied as Ceres' corrector does),
//   J = [J_m  J_k],  r,   H = J^T J,  b = J^T r,
// over the marginalized blocks m and the kept blocks k they connect to. Eliminating m,
//   H* = H_kk - H_km H_mm^+ H_mk,     b* = b_k - H_km H_mm^+ b_m,
// and with the Jacobi scaling W = diag(H*)^-1/2 (its coordinates are in different units) and the
// eigen-decomposition W H* W = V S V^T (eigenvalues below relative_eigen_floor times the largest
// dropped, so an unobservable direction carries no information rather than noise):
//   J* = S^1/2 V^T W^-1,   r0 = S^-1/2 V^T W b*,
// which is the MarginalizationFactor's prior (J*^T J* = H*, J*^T r0 = b*). The residual blocks
// and the marginalized parameter blocks are then removed from the problem; the caller adds the
// returned prior back as a MarginalizationFactor.
#pragma once

#include <vector>

#include <ceres/problem.h>

#include "factors/marginalization_factor.h"

namespace auvdock {

struct MarginalizationOptions {
  double relative_eigen_floor = 1e-12;  // eigenvalues of H* below this x the largest are dropped
};

// Marginalizes `blocks` out of `problem` and returns the prior on their neighbours (no blocks,
// empty J, when nothing else was connected). Pose blocks are recognised by their manifold
// (PoseManifold); every other kept block must be Euclidean (no manifold). The problem must not
// own its cost functions' parameter memory in a way that removal would invalidate the kept blocks.
// Throws std::invalid_argument if a block is not in the problem or a kept block has another
// manifold.
LinearizedPrior MarginalizeOut(ceres::Problem* problem, const std::vector<double*>& blocks,
                               const MarginalizationOptions& options = {});

// The dense information of a prior, H* = J*^T J* and b* = J*^T r0 (for tests and diagnostics).
void PriorInformation(const LinearizedPrior& prior, Eigen::MatrixXd* H, Eigen::VectorXd* b);

}  // namespace auvdock
