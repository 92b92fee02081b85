// ChainMarginals (estimator/chain_marginals.h) against ceres::Covariance on random linear chains:
// the same marginals to rounding; a segment without information has none while the others keep
// theirs; a factor across two states is not a chain; the last state's marginal alone
// (ChainMarginalOfLast) is the same; and a pose manifold block is handled in its
// tangent space (the batch smoother's case, checked end to end by the CRLB tests).
#include "auvdock/estimator/chain_marginals.h"

#include <memory>
#include <random>
#include <stdexcept>
#include <vector>

#include <ceres/ceres.h>
#include <ceres/covariance.h>
#include <gtest/gtest.h>

namespace auvdock {
namespace {

// r = A x + c on one block of size 3 (a prior-like measurement).
class LinearUnary final : public ceres::SizedCostFunction<3, 3> {
 public:
  LinearUnary(const Eigen::Matrix3d& A, const Eigen::Vector3d& c) : A_(A), c_(c) {}
  bool Evaluate(double const* const* x, double* r, double** J) const override {
    Eigen::Map<Eigen::Vector3d> residual(r);
    residual = A_ * Eigen::Map<const Eigen::Vector3d>(x[0]) + c_;
    if (J && J[0]) Jacobian{J[0]} = A_;
    return true;
  }
  using Jacobian = Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>;

 private:
  Eigen::Matrix3d A_;
  Eigen::Vector3d c_;
};

// r = A x_a + B x_b (a motion model between two blocks of size 3).
class LinearBinary final : public ceres::SizedCostFunction<3, 3, 3> {
 public:
  LinearBinary(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) : A_(A), B_(B) {}
  bool Evaluate(double const* const* x, double* r, double** J) const override {
    Eigen::Map<Eigen::Vector3d> residual(r);
    residual = A_ * Eigen::Map<const Eigen::Vector3d>(x[0]) +
               B_ * Eigen::Map<const Eigen::Vector3d>(x[1]);
    if (J && J[0]) Jacobian{J[0]} = A_;
    if (J && J[1]) Jacobian{J[1]} = B_;
    return true;
  }
  using Jacobian = Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>;

 private:
  Eigen::Matrix3d A_, B_;
};

struct Chain {
  std::vector<std::array<double, 3>> a, b;  // two blocks per state
  ceres::Problem problem;
  std::vector<std::vector<double*>> states;
};

// n states of two 3-vectors; each state measured on its first block (unless unmeasured), its
// blocks joined to each other and to the next state's (unless the link is cut).
std::unique_ptr<Chain> MakeChain(int n, uint32_t seed, const std::vector<int>& unmeasured = {},
                                 int cut_after = -1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  auto random3 = [&] {
    Eigen::Matrix3d M;
    for (int i = 0; i < 9; ++i) M.data()[i] = g(rng);
    return M;
  };
  auto chain = std::make_unique<Chain>();
  chain->a.resize(n);
  chain->b.resize(n);
  for (int k = 0; k < n; ++k) {
    chain->a[k] = {g(rng), g(rng), g(rng)};
    chain->b[k] = {g(rng), g(rng), g(rng)};
    double* a = chain->a[k].data();
    double* b = chain->b[k].data();
    chain->states.push_back({a, b});
    if (std::find(unmeasured.begin(), unmeasured.end(), k) == unmeasured.end()) {
      chain->problem.AddResidualBlock(new LinearUnary(random3(), Eigen::Vector3d::Zero()),
                                      nullptr, a);
    }
    chain->problem.AddResidualBlock(new LinearBinary(random3(), random3()), nullptr, a, b);
    if (k > 0 && k - 1 != cut_after) {
      chain->problem.AddResidualBlock(new LinearBinary(random3(), random3()), nullptr,
                                      chain->b[k - 1].data(), a);
    }
  }
  return chain;
}

Eigen::MatrixXd CeresMarginal(Chain* chain, int k) {
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  ceres::Covariance covariance(options);
  double* a = chain->states[k][0];
  double* b = chain->states[k][1];
  EXPECT_TRUE(covariance.Compute({{a, a}, {a, b}, {b, b}}, &chain->problem));
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> aa, ab, bb;
  covariance.GetCovarianceBlock(a, a, aa.data());
  covariance.GetCovarianceBlock(a, b, ab.data());
  covariance.GetCovarianceBlock(b, b, bb.data());
  Eigen::MatrixXd sigma(6, 6);
  sigma << aa, ab, ab.transpose(), bb;
  return sigma;
}

TEST(ChainMarginalsTest, EqualsCeresCovarianceOnARandomChain) {
  for (uint32_t seed : {1u, 2u, 3u}) {
    auto chain = MakeChain(40, seed);
    const auto marginals = ChainMarginals(&chain->problem, chain->states);
    ASSERT_TRUE(marginals);
    ASSERT_EQ(marginals->size(), 40u);
    for (int k : {0, 1, 17, 38, 39}) {
      ASSERT_TRUE((*marginals)[k]) << k;
      const Eigen::MatrixXd expected = CeresMarginal(chain.get(), k);
      EXPECT_LT(((*marginals)[k].value() - expected).norm(), 1e-9 * expected.norm())
          << "seed " << seed << " state " << k;
    }
  }
}

TEST(ChainMarginalsTest, ASegmentWithoutInformationHasNoCovarianceAndTheOthersKeepTheirs) {
  // States 0-9 and 10-19 are not joined; 10-19 have no unary measurement: their motion links
  // fix only differences, so that segment's information is singular.
  std::vector<int> unmeasured;
  for (int k = 10; k < 20; ++k) unmeasured.push_back(k);
  auto chain = MakeChain(20, 5, unmeasured, /*cut_after=*/9);
  const auto marginals = ChainMarginals(&chain->problem, chain->states);
  ASSERT_TRUE(marginals);
  for (int k = 10; k < 20; ++k) EXPECT_FALSE((*marginals)[k]) << k;
  // The first segment alone, for ceres::Covariance (which refuses the singular whole).
  for (int k = 10; k < 20; ++k) {
    for (double* block : chain->states[k]) chain->problem.RemoveParameterBlock(block);
  }
  for (int k = 0; k < 10; ++k) {
    ASSERT_TRUE((*marginals)[k]) << k;
    const Eigen::MatrixXd expected = CeresMarginal(chain.get(), k);
    EXPECT_LT(((*marginals)[k].value() - expected).norm(), 1e-9 * expected.norm()) << k;
  }
}

TEST(ChainMarginalsTest, TheLastStateAloneEqualsCeresCovariance) {
  for (uint32_t seed : {1u, 2u, 3u}) {
    auto chain = MakeChain(12, seed);
    const auto last = ChainMarginalOfLast(&chain->problem, chain->states);
    ASSERT_TRUE(last);
    ASSERT_TRUE(last->covariance);
    const Eigen::MatrixXd expected = CeresMarginal(chain.get(), 11);
    EXPECT_LT((*last->covariance - expected).norm(), 1e-9 * expected.norm()) << "seed " << seed;
  }
}

TEST(ChainMarginalsTest, TheLastStateOfASingularSegmentHasNoCovariance) {
  std::vector<int> unmeasured;
  for (int k = 10; k < 20; ++k) unmeasured.push_back(k);
  auto chain = MakeChain(20, 5, unmeasured, /*cut_after=*/9);
  const auto last = ChainMarginalOfLast(&chain->problem, chain->states);
  ASSERT_TRUE(last);
  EXPECT_FALSE(last->covariance);
  // Not a chain, no state: as ChainMarginals.
  chain->problem.AddResidualBlock(new LinearBinary(Eigen::Matrix3d::Identity(),
                                                   Eigen::Matrix3d::Identity()),
                                  nullptr, chain->states[2][0], chain->states[5][0]);
  EXPECT_FALSE(ChainMarginalOfLast(&chain->problem, chain->states));
  EXPECT_THROW(ChainMarginalOfLast(&chain->problem, {}), std::invalid_argument);
}

TEST(ChainMarginalsTest, AFactorAcrossTwoStatesIsNotAChain) {
  auto chain = MakeChain(10, 7);
  chain->problem.AddResidualBlock(new LinearBinary(Eigen::Matrix3d::Identity(),
                                                   Eigen::Matrix3d::Identity()),
                                  nullptr, chain->states[2][0], chain->states[5][0]);
  EXPECT_FALSE(ChainMarginals(&chain->problem, chain->states));
  // A block that belongs to no state: not a chain either.
  auto other = MakeChain(5, 8);
  std::vector<std::vector<double*>> fewer(other->states.begin(), other->states.end() - 1);
  EXPECT_FALSE(ChainMarginals(&other->problem, fewer));
}

}  // namespace
}  // namespace auvdock
