#include "auvdock/estimator/marginal_covariance.h"

#include <stdexcept>

#include <string>
#include <vector>

#include <ceres/covariance.h>
#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <gtest/gtest.h>

#include "factors/pose_manifold.h"
#include "tests/testing/small_pose_graph.h"

namespace auvdock {
namespace {

// Each block's marginal covariance equals the matching block of a dense (J^T J)^-1 built from
// the terms' own Jacobians in the tangent space.
TEST(MarginalCovarianceTest, EqualsTheDenseInverseOfTheInformation) {
  const PoseManifold manifold;
  ceres::Problem problem(test::NonOwningManifolds());
  test::SmallGraph g;
  test::BuildSmallGraph(&g, &problem, &manifold);
  const std::vector<double*> order = {g.pose[0], g.pose[1], g.pose[2], g.vec[0], g.vec[1]};
  Eigen::MatrixXd J;
  Eigen::VectorXd r;
  test::DenseTangentJacobian(g, order, manifold, {}, &J, &r);
  ASSERT_EQ(J.cols(), 24);
  const Eigen::MatrixXd covariance = (J.transpose() * J).inverse();

  int column = 0;
  for (double* block : order) {
    const int size = problem.ParameterBlockTangentSize(block);
    std::string reason;
    const auto sigma = MarginalCovariance(&problem, block, {}, &reason);
    ASSERT_TRUE(sigma.has_value()) << reason;
    const Eigen::MatrixXd expected = covariance.block(column, column, size, size);
    EXPECT_LT((*sigma - expected).cwiseAbs().maxCoeff(), 1e-8 * expected.cwiseAbs().maxCoeff())
        << "block at column " << column << "\n"
        << *sigma << "\nexpected\n"
        << expected;
    column += size;
  }
}

// With a robust loss on some residuals, the answer is Ceres' own (SPARSE_QR, loss applied).
TEST(MarginalCovarianceTest, EqualsCeresCovarianceWithRobustLosses) {
  const PoseManifold manifold;
  // Every term twice: once plain and once under a Huber loss whose linear part some residuals
  // reach (so the corrector's down-weighting is in play).
  ceres::Problem robust(test::NonOwningManifolds());
  test::SmallGraph h;
  test::BuildSmallGraph(&h, &robust, &manifold);
  std::vector<ceres::ResidualBlockId> ids;
  robust.GetResidualBlocks(&ids);
  for (ceres::ResidualBlockId id : ids) {
    std::vector<double*> blocks;
    robust.GetParameterBlocksForResidualBlock(id, &blocks);
    const ceres::CostFunction* cost = robust.GetCostFunctionForResidualBlock(id);
    robust.AddResidualBlock(const_cast<ceres::CostFunction*>(cost), new ceres::HuberLoss(0.5),
                            blocks);
  }
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::SPARSE_QR;
  options.apply_loss_function = true;
  ceres::Covariance reference(options);
  std::vector<std::pair<const double*, const double*>> pairs;
  for (double* block : {h.pose[0], h.pose[2], h.vec[1]}) pairs.emplace_back(block, block);
  ASSERT_TRUE(reference.Compute(pairs, &robust));
  for (double* block : {h.pose[0], h.pose[2], h.vec[1]}) {
    const int size = robust.ParameterBlockTangentSize(block);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> expected(size, size);
    ASSERT_TRUE(reference.GetCovarianceMatrixInTangentSpace({block}, expected.data()));
    const auto sigma = MarginalCovariance(&robust, block);
    ASSERT_TRUE(sigma.has_value());
    EXPECT_LT((*sigma - Eigen::MatrixXd(expected)).cwiseAbs().maxCoeff(),
              1e-8 * expected.cwiseAbs().maxCoeff());
  }
}

// Without the absolute prior the chain floats (a 6-DoF gauge freedom): no covariance, a reason.
TEST(MarginalCovarianceTest, RankDeficientInformationGivesNoCovarianceAndAReason) {
  const PoseManifold manifold;
  ceres::Problem problem(test::NonOwningManifolds());
  test::SmallGraph g;
  test::BuildSmallGraph(&g, &problem, &manifold, /*with_prior=*/false);
  std::string reason;
  EXPECT_FALSE(MarginalCovariance(&problem, g.pose[1], {}, &reason).has_value());
  EXPECT_NE(reason.find("rank-deficient"), std::string::npos) << reason;
}

TEST(MarginalCovarianceTest, RejectsABlockNotInTheProblem) {
  ceres::Problem problem;
  double x[3] = {0, 0, 0};
  EXPECT_THROW(MarginalCovariance(&problem, x), std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
