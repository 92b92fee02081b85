// Rigid alignment of two matched 3-D point sets (weighted Kabsch / Umeyama without scale):
// the pose of the dock from lights triangulated by the stereo pair (seed 000, section 3.3.2).
//
// Problem (seed 000 eq. 17, with weights w_i >= 0):
//   (R, T) = argmin sum_i w_i |R p_i + T - q_i|^2,   p_i = src[i], q_i = dst[i],   det R = +1.
// Solution (eqs. 18-23):
//   p0 = sum w_i p_i / sum w_i,  q0 = sum w_i q_i / sum w_i            (weighted centroids)
//   H  = sum w_i (p_i - p0)(q_i - q0)^T = U S V^T                       (SVD, eq. 20)
//   R  = V diag(1, 1, det(V U^T)) U^T                                   (eq. 22, reflection fix)
//   T  = q0 - R p0                                                      (eq. 23)
// The diag(1, 1, det(V U^T)) factor turns the best orthogonal fit into the best rotation when
// the former is a reflection (noisy, or coplanar points where the sign of the third singular
// vectors is arbitrary). The dock lights are coplanar, so this case is the normal one.
//
// Frames and units: src in frame "src", dst in frame "dst", metres; the result T_dst_src maps
// src coordinates into dst: q ≈ T_dst_src * p. For the stereo pose, src = the dock lights p_D
// and dst = their triangulated positions p_S in the stereo (left camera) frame, giving T_S_D.
//
// Weights are scalars. Triangulated points are really anisotropic (depth is the weak
// direction), but a 3x3 information per point has no closed form; that weighting belongs to
// the estimator's stereo factor, and this function only gives a good closed-form start.
//
// Reference: seed 000 (Zhu et al., Control and Decision 2025, eqs. 17-23); Umeyama, IEEE PAMI
// 13(4), 1991; Kabsch, Acta Cryst. A32, 1976.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "auvdock/geometry/pose3.h"

namespace auvdock {

struct AlignmentResult {
  bool ok = false;
  std::string reason;  // why not ok (empty when ok)
  Pose3 T_dst_src;     // dst = T_dst_src * src
  double rms_m = 0.0;  // weighted RMS residual sqrt(sum w_i |T p_i - q_i|^2 / sum w_i), metres
};

// src[i] and dst[i] are the same point in the two frames. weights: empty (all 1) or one finite
// non-negative weight per point. ok = false with a reason for: fewer than 3 points (or fewer
// than 3 with positive weight), size mismatch, NaN/Inf coordinates or weights, negative
// weights, and points that are (numerically) collinear or coincident, which leave the rotation
// about their line free.
AlignmentResult AlignPointSets(const std::vector<Eigen::Vector3d>& src,
                               const std::vector<Eigen::Vector3d>& dst,
                               const std::vector<double>& weights = {});

}  // namespace auvdock
