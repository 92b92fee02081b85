// Two cost functions on one pose block (factors/pose_manifold.h) that must agree: the residuals,
// and the Jacobians in the pose's tangent space (the ambient 7-column Jacobian times the
// manifold's PlusJacobian, the only part Ceres uses). For factors whose analytic Jacobian
// (factors/analytic_pose_cost_function.h) is checked against ceres::Jet's.
#pragma once

#include <ceres/cost_function.h>
#include <Eigen/Core>
#include <gtest/gtest.h>

#include "factors/pose_manifold.h"

namespace auvdock::test {

template <int kResiduals>
void ExpectSameTangentJacobian(const ceres::CostFunction& analytic,
                               const ceres::CostFunction& automatic, const double* pose_block) {
  const double* params[1] = {pose_block};
  Eigen::Matrix<double, kResiduals, 1> r_analytic, r_automatic, r_only;
  Eigen::Matrix<double, kResiduals, kPoseSize, Eigen::RowMajor> J_analytic, J_automatic;
  double* jacobians_analytic[1] = {J_analytic.data()};
  double* jacobians_automatic[1] = {J_automatic.data()};
  ASSERT_TRUE(analytic.Evaluate(params, r_analytic.data(), jacobians_analytic));
  ASSERT_TRUE(automatic.Evaluate(params, r_automatic.data(), jacobians_automatic));
  EXPECT_LT((r_analytic - r_automatic).norm(), 1e-9 * (1.0 + r_automatic.norm()));
  Eigen::Matrix<double, kPoseSize, kPoseTangentSize, Eigen::RowMajor> plus;
  ASSERT_TRUE(PoseManifold().PlusJacobian(pose_block, plus.data()));
  const Eigen::Matrix<double, kResiduals, kPoseTangentSize> tangent_analytic = J_analytic * plus;
  const Eigen::Matrix<double, kResiduals, kPoseTangentSize> tangent_automatic = J_automatic * plus;
  EXPECT_LT((tangent_analytic - tangent_automatic).norm(), 1e-9 * tangent_automatic.norm())
      << "analytic\n" << tangent_analytic << "\nautomatic\n" << tangent_automatic;
  // Residuals alone (no Jacobian asked for): the same residual.
  ASSERT_TRUE(analytic.Evaluate(params, r_only.data(), nullptr));
  EXPECT_EQ(r_only, r_analytic);
}

}  // namespace auvdock::test
