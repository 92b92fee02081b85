// Closed-form rigid (SE(3), no scale) alignment of an estimated trajectory to the truth.
//
// Given matched positions p_est_i (the estimate's dock frame) and p_true_i (the true dock
// frame D), finds the rigid transform T_align = (R, t) minimizing
//   sum_i |R p_est_i + t - p_true_i|^2,
// so that T_align * p_est ≈ p_true. Applied to whole poses, T_D_B ≈ T_align * T_Dest_B.
//
// Math (Umeyama, "Least-squares estimation of transformation parameters between two point
// patterns", IEEE PAMI 1991, with c = 1; Horn 1987 for the same problem with quaternions):
//   mu_e, mu_t = centroids;  S = 1/n sum (p_true_i - mu_t)(p_est_i - mu_e)^T = U D V^T (SVD)
//   R = U diag(1, 1, det(U) det(V)) V^T,  t = mu_t - R mu_e.
// The diag(1, 1, ±1) factor is the reflection fix: it makes det(R) = +1 even when the best
// orthogonal fit would be a reflection (noisy or planar data). Using det(U) det(V) rather than
// sign(det S) keeps the answer right when the points are coplanar (rank S = 2), which is the
// common case of an AUV holding depth.
//
// The rotation is unique only if rank S >= 2, i.e. the points are not all collinear (and not
// all equal); otherwise InputError. Units: metres in, metres out.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "auvdock/geometry/pose3.h"

namespace auvdock {

// p_est and p_true are matched element by element and must have the same size (asserted).
// Throws InputError("SE(3) alignment needs at least 3 non-collinear positions") if there are
// fewer than 3 pairs or the pairs do not fix the rotation.
Pose3 AlignPositionsSE3(const std::vector<Eigen::Vector3d>& p_est,
                        const std::vector<Eigen::Vector3d>& p_true);

}  // namespace auvdock
