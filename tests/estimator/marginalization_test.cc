#include "auvdock/estimator/marginalization.h"

#include <algorithm>
#include <memory>
#include <random>

#include <ceres/autodiff_cost_function.h>
#include <ceres/gradient_checker.h>
#include <ceres/solver.h>
#include <gtest/gtest.h>

#include "factors/marginalization_factor.h"
#include "factors/pose_manifold.h"
#include "tests/testing/small_pose_graph.h"

namespace auvdock {
namespace {

using test::BuildSmallGraph;
using test::NonOwningManifolds;
using test::RandomRotation;
using test::SmallGraph;

// Dense reference: each term's ambient Jacobian from its own Evaluate, times the manifold's
// PlusJacobian, stacked over [x0 | pose1, vec0] and Schur-complemented with a full inverse.
TEST(MarginalizationTest, PriorEqualsDenseSchurComplementReference) {
  const PoseManifold manifold;
  ceres::Problem problem(NonOwningManifolds());
  SmallGraph g;
  BuildSmallGraph(&g, &problem, &manifold);

  // Reference columns: x0 (6) | pose1 (6) | vec0 (3), over the terms that touch x0.
  Eigen::MatrixXd J;
  Eigen::VectorXd r;
  test::DenseTangentJacobian(g, {g.pose[0], g.pose[1], g.vec[0]}, manifold, {g.pose[0]}, &J, &r);
  ASSERT_EQ(J.cols(), 15);
  const Eigen::MatrixXd H = J.transpose() * J;
  const Eigen::VectorXd b = J.transpose() * r;
  const Eigen::MatrixXd H_mm = H.topLeftCorner(6, 6);
  const Eigen::MatrixXd H_km = H.bottomLeftCorner(9, 6);
  const Eigen::MatrixXd H_ref =
      H.bottomRightCorner(9, 9) - H_km * H_mm.inverse() * H_km.transpose();
  const Eigen::VectorXd b_ref = b.tail(9) - H_km * H_mm.inverse() * b.head(6);

  // The prior's block order is Ceres' (unspecified); the reference follows it.
  const std::vector<double*> original = {g.pose[1], g.vec[0]};
  const LinearizedPrior prior = MarginalizeOut(&problem, {g.pose[0]});
  ASSERT_EQ(prior.blocks.size(), 2u);
  std::vector<double*> prior_order;
  for (const LinearizedPrior::Block& block : prior.blocks) {
    prior_order.push_back(block.parameters);
    EXPECT_EQ(block.kind, block.parameters == g.vec[0] ? MarginalBlockKind::kEuclidean
                                                      : MarginalBlockKind::kPose);
    // Linearised at the values it had.
    EXPECT_EQ(block.linearization_point[0], block.parameters[0]);
  }
  EXPECT_TRUE(std::is_permutation(prior_order.begin(), prior_order.end(), original.begin()));
  // Permute the reference to the prior's order.
  const bool swapped = prior_order[0] == g.vec[0];
  Eigen::PermutationMatrix<Eigen::Dynamic> perm(9);
  for (int i = 0; i < 9; ++i) perm.indices()[i] = swapped ? (i < 3 ? 6 + i : i - 3) : i;
  const Eigen::MatrixXd H_expected = perm.transpose() * H_ref * perm;
  const Eigen::VectorXd b_expected = perm.transpose() * b_ref;
  Eigen::MatrixXd H_star;
  Eigen::VectorXd b_star;
  PriorInformation(prior, &H_star, &b_star);
  EXPECT_LT((H_star - H_expected).cwiseAbs().maxCoeff(), 1e-8) << H_star - H_expected;
  EXPECT_LT((b_star - b_expected).cwiseAbs().maxCoeff(), 1e-8);

  // The marginalized block and its residual blocks are gone; the others remain.
  EXPECT_FALSE(problem.HasParameterBlock(g.pose[0]));
  EXPECT_EQ(problem.NumResidualBlocks(), 2);
}

// For a linear-Gaussian problem, marginalizing is exact: the kept variables' optimum with the
// prior equals the full problem's optimum.
struct LinearCost {
  LinearCost(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B, const Eigen::Vector3d& c)
      : A_(A), B_(B), c_(c) {}
  template <typename T>
  bool operator()(const T* x, const T* y, T* r) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> xv(x), yv(y);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> residual(r);
    residual = A_.cast<T>() * xv + B_.cast<T>() * yv - c_.cast<T>();
    return true;
  }
  Eigen::Matrix3d A_, B_;
  Eigen::Vector3d c_;
};

TEST(MarginalizationTest, LinearChainKeepsTheFullProblemsOptimum) {
  constexpr int kN = 5;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<LinearCost> terms;
  for (int i = 0; i + 1 < kN; ++i) {
    Eigen::Matrix3d A, B;
    Eigen::Vector3d c;
    for (int k = 0; k < 9; ++k) {
      A(k) = n(rng);
      B(k) = n(rng);
    }
    for (int k = 0; k < 3; ++k) c[k] = n(rng);
    A += 3.0 * Eigen::Matrix3d::Identity();
    terms.emplace_back(A, B, c);
  }
  Eigen::Vector3d anchor(n(rng), n(rng), n(rng));

  auto build = [&](ceres::Problem* problem, double (*x)[3]) {
    for (int i = 0; i < kN; ++i) {
      for (int k = 0; k < 3; ++k) x[i][k] = 0.1 * i;
    }
    problem->AddResidualBlock(
        new ceres::AutoDiffCostFunction<LinearCost, 3, 3, 3>(new LinearCost(
            Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Zero(), anchor)),
        nullptr, x[0], x[1]);
    for (int i = 0; i + 1 < kN; ++i) {
      problem->AddResidualBlock(
          new ceres::AutoDiffCostFunction<LinearCost, 3, 3, 3>(new LinearCost(terms[i])), nullptr,
          x[i], x[i + 1]);
    }
  };
  ceres::Solver::Options solver;
  solver.max_num_iterations = 20;
  solver.function_tolerance = 1e-16;
  solver.gradient_tolerance = 1e-16;
  solver.parameter_tolerance = 1e-16;
  ceres::Solver::Summary summary;

  double full[kN][3];
  ceres::Problem full_problem;
  build(&full_problem, full);
  ceres::Solve(solver, &full_problem, &summary);

  double window[kN][3];
  ceres::Problem window_problem(NonOwningManifolds());
  build(&window_problem, window);
  LinearizedPrior prior = MarginalizeOut(&window_problem, {window[0], window[1]});
  auto* factor = new MarginalizationFactor(std::move(prior));
  window_problem.AddResidualBlock(factor, nullptr, factor->parameter_blocks());
  ceres::Solve(solver, &window_problem, &summary);
  for (int i = 2; i < kN; ++i) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(window[i][k], full[i][k], 1e-9) << i << "," << k;
  }
}

TEST(MarginalizationTest, FactorJacobiansPassTheGradientCheckerAwayFromTheLinearizationPoint) {
  const PoseManifold manifold;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  LinearizedPrior prior;
  double pose[7], vec[3];
  const Eigen::Quaterniond q0 = RandomRotation(rng, 1.0);
  LinearizedPrior::Block pose_block;
  pose_block.parameters = pose;
  pose_block.kind = MarginalBlockKind::kPose;
  pose_block.linearization_point.resize(7);
  pose_block.linearization_point << 1.0, -2.0, 0.5, q0.x(), q0.y(), q0.z(), q0.w();
  LinearizedPrior::Block vec_block;
  vec_block.parameters = vec;
  vec_block.linearization_point = Eigen::Vector3d(0.3, 0.2, -0.1);
  prior.blocks = {pose_block, vec_block};
  prior.sqrt_information = Eigen::MatrixXd::Random(9, 9) + 4.0 * Eigen::MatrixXd::Identity(9, 9);
  prior.residual = Eigen::VectorXd::Random(9);
  const MarginalizationFactor factor(prior);

  // At the linearization point the residual is r0; away from it the gradient checker passes.
  const Eigen::Quaterniond q = RandomRotation(rng, 0.2) * q0;
  const double x_pose[7] = {1.1, -2.05, 0.6, q.x(), q.y(), q.z(), q.w()};
  const double x_vec[3] = {0.35, 0.1, -0.12};
  const double* params[2] = {x_pose, x_vec};
  std::vector<const ceres::Manifold*> manifolds = {&manifold, nullptr};
  ceres::NumericDiffOptions numeric;
  ceres::GradientChecker checker(&factor, &manifolds, numeric);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(params, 1e-7, &results)) << results.error_log;

  const double* at_x0[2] = {pose_block.linearization_point.data(),
                            vec_block.linearization_point.data()};
  Eigen::VectorXd r(9);
  ASSERT_TRUE(factor.Evaluate(at_x0, r.data(), nullptr));
  EXPECT_LT((r - prior.residual).norm(), 1e-12);
}

}  // namespace
}  // namespace auvdock
