// A cost function that also gives its Jacobians in its parameter blocks' tangent spaces, the
// spaces a solver steps in (factors/pose_manifold.h for a pose: dp, dtheta).
//
// Ceres asks every cost function for Jacobians in the blocks' ambient (stored) coordinates and
// multiplies a manifold block's by its PlusJacobian; the analytic factors compute the tangent
// Jacobian first and lift it to the ambient coordinates with MinusJacobian, so that
// J_ambient PlusJacobian = J_tangent exactly. A solver that works in the tangent spaces itself
// (estimator/chain_linearization.h) asks for J_tangent directly and skips both products: at the
// window's ~75 residual blocks and 6 linearisations a frame, the lift and its undoing were a tenth
// of the update's time (2026-12-06).
#pragma once

namespace auvdock {

class TangentJacobians {
 public:
  virtual ~TangentJacobians() = default;
  // As ceres::CostFunction::Evaluate (the same residuals), with jacobians[i] (row-major,
  // num_residuals x block i's tangent size; nullptr: not wanted) in block i's tangent space.
  virtual bool EvaluateInTangentSpace(double const* const* parameters, double* residuals,
                                      double** jacobians) const = 0;
};

}  // namespace auvdock
