// A Ceres cost function on one pose block from a factor that gives its residual and the
// residual's Jacobian in the pose's tangent space (dp, dtheta of factors/pose_manifold.h):
//
//   bool Factor::EvaluateTangent(const double* pose_D_B, double* residuals,
//                                Eigen::Matrix<double, kResiduals, 6, Eigen::RowMajor>* J) const;
//
// (J may be null: residuals only; false: not evaluable, as a Ceres functor's false.)
//
// Ceres asks for the Jacobian in the block's 7 ambient numbers and multiplies it by the
// manifold's PlusJacobian (7 x 6). The ambient Jacobian given here is J_tangent MinusJacobian(x)
// (6 x 7, the manifold's "lift"), so J_ambient PlusJacobian = J_tangent exactly (MinusJacobian
// PlusJacobian = I6): the same lift as the analytic IMU factor. The factor's tests check
// EvaluateTangent against the automatic derivative of its templated operator() and against
// Ceres' GradientChecker.
//
// Why: the window evaluates every vision residual's Jacobian at each solver iteration; the
// analytic form replaces a 7-dimensional ceres::Jet evaluation of the whole projection.
#pragma once

#include <memory>
#include <type_traits>

#include <ceres/sized_cost_function.h>
#include <Eigen/Core>

#include "factors/pose_manifold.h"
#include "factors/tangent_jacobians.h"

namespace auvdock {

template <typename Factor, int kResiduals>
class AnalyticPoseCostFunction : public ceres::SizedCostFunction<kResiduals, kPoseSize>,
                                 public TangentJacobians {
 public:
  using TangentJacobian = Eigen::Matrix<double, kResiduals, kPoseTangentSize, Eigen::RowMajor>;

  explicit AnalyticPoseCostFunction(std::unique_ptr<Factor> factor) : factor_(std::move(factor)) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* pose = parameters[0];
    if (jacobians == nullptr || jacobians[0] == nullptr) {
      return factor_->EvaluateTangent(pose, residuals, nullptr);
    }
    TangentJacobian J;
    if (!factor_->EvaluateTangent(pose, residuals, &J)) return false;
    Eigen::Matrix<double, kPoseTangentSize, kPoseSize, Eigen::RowMajor> lift;
    PoseManifold().MinusJacobian(pose, lift.data());
    Eigen::Map<Eigen::Matrix<double, kResiduals, kPoseSize, Eigen::RowMajor>> ambient(
        jacobians[0]);
    ambient = J * lift;
    return true;
  }

  // J_tangent as the factor gives it, not lifted (tangent_jacobians.h).
  bool EvaluateInTangentSpace(double const* const* parameters, double* residuals,
                              double** jacobians) const override {
    if (jacobians == nullptr || jacobians[0] == nullptr) {
      return factor_->EvaluateTangent(parameters[0], residuals, nullptr);
    }
    TangentJacobian J;
    if (!factor_->EvaluateTangent(parameters[0], residuals, &J)) return false;
    Eigen::Map<TangentJacobian> out(jacobians[0]);
    out = J;
    return true;
  }

  const Factor& factor() const { return *factor_; }

 private:
  std::unique_ptr<Factor> factor_;
};

// Whether a factor provides EvaluateTangent (see above).
template <typename Factor, typename = void>
struct HasTangentJacobian : std::false_type {};
template <typename Factor>
struct HasTangentJacobian<Factor, std::void_t<decltype(&Factor::EvaluateTangent)>>
    : std::true_type {};

}  // namespace auvdock
