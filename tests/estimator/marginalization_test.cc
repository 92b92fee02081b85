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

namespace auvdock {
namespace {

// Test residual: pose b relative to pose a, against a measured relative pose (6), unit weights.
struct RelativePoseCost {
  RelativePoseCost(const Eigen::Vector3d& p_ab, const Eigen::Quaterniond& q_ab)
      : p_ab_(p_ab), q_ab_(q_ab) {}
  template <typename T>
  bool operator()(const T* a, const T* b, T* r) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> pa(a), pb(b);
    const Eigen::Map<const Eigen::Quaternion<T>> qa(a + 3), qb(b + 3);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> rp(r), rq(r + 3);
    rp = qa.conjugate() * (pb - pa) - p_ab_.cast<T>();
    rq = QuaternionLog<T>(q_ab_.conjugate().cast<T>() * qa.conjugate() * qb);
    return true;
  }
  Eigen::Vector3d p_ab_;
  Eigen::Quaterniond q_ab_;
};

// Test residual: a Euclidean 3-vector v against a pose, r = R^T v - m (3).
struct BodyVectorCost {
  explicit BodyVectorCost(const Eigen::Vector3d& m) : m_(m) {}
  template <typename T>
  bool operator()(const T* pose, const T* v, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(pose + 3);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> vv(v);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> residual(r);
    residual = q.conjugate() * vv - m_.cast<T>();
    return true;
  }
  Eigen::Vector3d m_;
};

// Test residual: absolute pose prior (6), scaled.
struct PosePriorCost {
  template <typename T>
  bool operator()(const T* x, T* r) const {
    for (int i = 0; i < 3; ++i) r[i] = T(3.0) * x[i];
    const Eigen::Map<const Eigen::Quaternion<T>> q(x + 3);
    Eigen::Map<Eigen::Matrix<T, 3, 1>>(r + 3) = T(5.0) * QuaternionLog<T>(q);
    return true;
  }
};

Eigen::Quaterniond RandomRotation(std::mt19937_64& rng, double sigma) {
  std::normal_distribution<double> n(0.0, sigma);
  return QuaternionExp<double>(Eigen::Vector3d(n(rng), n(rng), n(rng)));
}

struct SmallGraph {
  // Three poses (x0 to be marginalized) and two velocity-like vectors.
  double pose[3][7];
  double vec[2][3];
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;  // for the reference
  struct Term {
    ceres::CostFunction* cost;
    std::vector<double*> blocks;
  };
  std::vector<Term> terms;
};

void BuildSmallGraph(SmallGraph* g, ceres::Problem* problem, const PoseManifold* manifold) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  for (auto& pose : g->pose) {
    const Eigen::Quaterniond q = RandomRotation(rng, 0.6);
    for (int k = 0; k < 3; ++k) pose[k] = n(rng);
    for (int k = 0; k < 4; ++k) pose[3 + k] = q.coeffs()[k];
  }
  for (auto& v : g->vec) {
    for (double& x : v) x = n(rng);
  }
  auto add = [&](ceres::CostFunction* cost, std::vector<double*> blocks) {
    g->terms.push_back({cost, blocks});
    problem->AddResidualBlock(cost, nullptr, blocks);
  };
  for (int i = 0; i < 2; ++i) {
    add(new ceres::AutoDiffCostFunction<RelativePoseCost, 6, 7, 7>(new RelativePoseCost(
            Eigen::Vector3d(n(rng), n(rng), n(rng)), RandomRotation(rng, 0.3))),
        {g->pose[i], g->pose[i + 1]});
  }
  add(new ceres::AutoDiffCostFunction<PosePriorCost, 6, 7>(new PosePriorCost), {g->pose[0]});
  add(new ceres::AutoDiffCostFunction<BodyVectorCost, 3, 7, 3>(
          new BodyVectorCost(Eigen::Vector3d(n(rng), n(rng), n(rng)))),
      {g->pose[0], g->vec[0]});
  add(new ceres::AutoDiffCostFunction<BodyVectorCost, 3, 7, 3>(
          new BodyVectorCost(Eigen::Vector3d(n(rng), n(rng), n(rng)))),
      {g->pose[1], g->vec[1]});
  for (auto& pose : g->pose) problem->SetManifold(pose, const_cast<PoseManifold*>(manifold));
}

ceres::Problem::Options NonOwningManifolds() {
  ceres::Problem::Options options;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.enable_fast_removal = true;
  return options;
}

// Dense reference: each term's ambient Jacobian from its own Evaluate, times the manifold's
// PlusJacobian, stacked over [x0 | pose1, vec0] and Schur-complemented with a full inverse.
TEST(MarginalizationTest, PriorEqualsDenseSchurComplementReference) {
  const PoseManifold manifold;
  ceres::Problem problem(NonOwningManifolds());
  SmallGraph g;
  BuildSmallGraph(&g, &problem, &manifold);

  // Reference columns: x0 (6) | pose1 (6) | vec0 (3).
  const std::vector<double*> order = {g.pose[0], g.pose[1], g.vec[0]};
  auto column_of = [&](double* block) {
    int col = 0;
    for (double* b : order) {
      if (b == block) return col;
      col += b == g.vec[0] ? 3 : 6;
    }
    return -1;
  };
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(15, 15);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(15);
  for (const SmallGraph::Term& term : g.terms) {
    if (std::find(term.blocks.begin(), term.blocks.end(), g.pose[0]) == term.blocks.end()) {
      continue;
    }
    const int m = term.cost->num_residuals();
    Eigen::VectorXd r(m);
    std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J_amb;
    std::vector<double*> jac_ptrs;
    for (double* block : term.blocks) {
      J_amb.emplace_back(m, block == g.vec[0] ? 3 : 7);
    }
    for (auto& J : J_amb) jac_ptrs.push_back(J.data());
    std::vector<const double*> params(term.blocks.begin(), term.blocks.end());
    ASSERT_TRUE(term.cost->Evaluate(params.data(), r.data(), jac_ptrs.data()));
    Eigen::MatrixXd J_full = Eigen::MatrixXd::Zero(m, 15);
    for (size_t i = 0; i < term.blocks.size(); ++i) {
      double* block = term.blocks[i];
      const int col = column_of(block);
      if (block == g.vec[0]) {
        J_full.middleCols(col, 3) = J_amb[i];
      } else {
        Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus;
        manifold.PlusJacobian(block, plus.data());
        J_full.middleCols(col, 6) = J_amb[i] * plus;
      }
    }
    H += J_full.transpose() * J_full;
    b += J_full.transpose() * r;
  }
  const Eigen::MatrixXd H_mm = H.topLeftCorner(6, 6);
  const Eigen::MatrixXd H_km = H.bottomLeftCorner(9, 6);
  const Eigen::MatrixXd H_ref = H.bottomRightCorner(9, 9) - H_km * H_mm.inverse() * H_km.transpose();
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
