// The chain's linearisation (estimator/chain_linearization.h) and Levenberg-Marquardt solver
// (estimator/chain_solver.h) against Ceres on a nonlinear chain with a quaternion manifold and
// robust losses: the same cost, gradient and Gauss-Newton information as Problem::Evaluate (its
// robust-loss corrector included, on both of its branches), the same minimum as ceres::Solve;
// a problem that is not a chain is left to the caller untouched; the stopping rules hold.
#include "auvdock/estimator/chain_solver.h"

#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <stdexcept>
#include <vector>

#include <ceres/ceres.h>
#include <ceres/crs_matrix.h>
#include <gtest/gtest.h>

#include "auvdock/estimator/chain_linearization.h"

namespace auvdock {
namespace {

// The range from a position (2-D) to a beacon: r = (|p - b| - d) / sigma.
struct RangeResidual {
  RangeResidual(double bx, double by, double d) : bx(bx), by(by), d(d) {}
  template <typename T>
  bool operator()(const T* p, T* r) const {
    const T dx = p[0] - bx, dy = p[1] - by;
    r[0] = (sqrt(dx * dx + dy * dy) - d) / 0.05;
    return true;
  }
  double bx, by, d;
};

// Motion between neighbours: the position moves by u in the frame of the attitude q (a unit
// quaternion, Eigen order x y z w; rotation about z), and the attitude turns by w about z.
struct MotionResidual {
  MotionResidual(double ux, double uy, double w) : ux(ux), uy(uy), w(w) {}
  template <typename T>
  bool operator()(const T* p0, const T* q0, const T* p1, const T* q1, T* r) const {
    const Eigen::Quaternion<T> a(q0[3], q0[0], q0[1], q0[2]);
    const Eigen::Quaternion<T> b(q1[3], q1[0], q1[1], q1[2]);
    const Eigen::Matrix<T, 3, 1> u = a * Eigen::Matrix<T, 3, 1>(T(ux), T(uy), T(0));
    r[0] = (p1[0] - p0[0] - u[0]) / 0.02;
    r[1] = (p1[1] - p0[1] - u[1]) / 0.02;
    const Eigen::Quaternion<T> turn(Eigen::AngleAxis<T>(T(w), Eigen::Matrix<T, 3, 1>::UnitZ()));
    const Eigen::Quaternion<T> e = (a * turn).conjugate() * b;
    r[2] = T(2) * e.x() / 0.01;
    r[3] = T(2) * e.y() / 0.01;
    r[4] = T(2) * e.z() / 0.01;
    return true;
  }
  double ux, uy, w;
};

// An attitude measurement (a compass): the yaw part of q against a heading, and its tilt.
struct HeadingResidual {
  explicit HeadingResidual(double yaw) : yaw(yaw) {}
  template <typename T>
  bool operator()(const T* q, T* r) const {
    const Eigen::Quaternion<T> a(q[3], q[0], q[1], q[2]);
    const Eigen::Quaternion<T> m(Eigen::AngleAxis<T>(T(yaw), Eigen::Matrix<T, 3, 1>::UnitZ()));
    const Eigen::Quaternion<T> e = m.conjugate() * a;
    r[0] = T(2) * e.x() / 0.05;
    r[1] = T(2) * e.y() / 0.05;
    r[2] = T(2) * e.z() / 0.05;
    return true;
  }
  double yaw;
};

struct Chain {
  std::vector<std::array<double, 2>> p;
  std::vector<std::array<double, 4>> q;
  std::unique_ptr<ceres::Problem> problem;
  std::vector<std::vector<double*>> states;
};

// n states along an arc, measured with noise and one gross range outlier, started away from the
// truth. loss: for every range and heading residual (nullptr: none).
Chain MakeChain(int n, std::function<ceres::LossFunction*()> loss, unsigned seed = 3) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  Chain c;
  c.p.resize(n);
  c.q.resize(n);
  ceres::Problem::Options options;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  c.problem = std::make_unique<ceres::Problem>(options);
  static ceres::EigenQuaternionManifold quaternion;
  const std::array<std::array<double, 2>, 3> beacons{{{0.0, 5.0}, {4.0, -3.0}, {-5.0, -1.0}}};
  std::vector<std::array<double, 2>> truth(n);
  std::vector<double> yaw(n);
  for (int k = 0; k < n; ++k) {
    yaw[k] = 0.1 * k;
    truth[k] = {2.0 * std::sin(0.1 * k), 2.0 - 2.0 * std::cos(0.1 * k)};
    c.p[k] = {truth[k][0] + 0.3 * noise(rng), truth[k][1] + 0.3 * noise(rng)};
    const Eigen::Quaterniond start(
        Eigen::AngleAxisd(yaw[k] + 0.1 * noise(rng), Eigen::Vector3d::UnitZ()) *
        Eigen::AngleAxisd(0.05 * noise(rng), Eigen::Vector3d::UnitX()));
    c.q[k] = {start.x(), start.y(), start.z(), start.w()};
  }
  for (int k = 0; k < n; ++k) {
    c.problem->AddParameterBlock(c.p[k].data(), 2);
    c.problem->AddParameterBlock(c.q[k].data(), 4, &quaternion);
    c.states.push_back({c.p[k].data(), c.q[k].data()});
    for (size_t b = 0; b < beacons.size(); ++b) {
      const double dx = truth[k][0] - beacons[b][0], dy = truth[k][1] - beacons[b][1];
      double d = std::hypot(dx, dy) + 0.05 * noise(rng);
      if (k == n / 2 && b == 0) d += 1.0;  // a gross outlier
      c.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<RangeResidual, 1, 2>(
                                      new RangeResidual(beacons[b][0], beacons[b][1], d)),
                                  loss ? loss() : nullptr, c.p[k].data());
    }
    c.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<HeadingResidual, 3, 4>(
                                    new HeadingResidual(yaw[k] + 0.05 * noise(rng))),
                                loss ? loss() : nullptr, c.q[k].data());
    if (k + 1 < n) {
      // Body-frame motion from the truth: the chord in the frame of attitude k.
      const double cx = 2.0 * std::sin(0.1 * (k + 1)) - truth[k][0];
      const double cy = 2.0 - 2.0 * std::cos(0.1 * (k + 1)) - truth[k][1];
      const double ux = std::cos(yaw[k]) * cx + std::sin(yaw[k]) * cy;
      const double uy = -std::sin(yaw[k]) * cx + std::cos(yaw[k]) * cy;
      c.problem->AddResidualBlock(
          new ceres::AutoDiffCostFunction<MotionResidual, 5, 2, 4, 2, 4>(
              new MotionResidual(ux + 0.02 * noise(rng), uy + 0.02 * noise(rng), 0.1)),
          nullptr, c.p[k].data(), c.q[k].data(), c.p[k + 1].data(), c.q[k + 1].data());
    }
  }
  return c;
}

// Ceres' own cost, gradient and J^T J (dense) at the current values, blocks in chain order.
struct Reference {
  double cost = 0.0;
  Eigen::VectorXd gradient;
  Eigen::MatrixXd H;
};
Reference Evaluate(Chain& c) {
  ceres::Problem::EvaluateOptions options;
  for (const auto& s : c.states)
    options.parameter_blocks.insert(options.parameter_blocks.end(), s.begin(), s.end());
  Reference ref;
  std::vector<double> gradient;
  ceres::CRSMatrix crs;
  EXPECT_TRUE(c.problem->Evaluate(options, &ref.cost, nullptr, &gradient, &crs));
  ref.gradient = Eigen::Map<Eigen::VectorXd>(gradient.data(), gradient.size());
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int i = crs.rows[r]; i < crs.rows[r + 1]; ++i) J(r, crs.cols[i]) = crs.values[i];
  }
  ref.H = J.transpose() * J;
  return ref;
}

Eigen::MatrixXd Dense(const ChainLinearization& lin, const ChainLayout& layout) {
  const int n = layout.num_states();
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(layout.start[n], layout.start[n]);
  for (int k = 0; k < n; ++k) {
    H.block(layout.start[k], layout.start[k], layout.state_size(k), layout.state_size(k)) =
        lin.D[k];
    if (k + 1 < n) {
      H.block(layout.start[k], layout.start[k + 1], layout.state_size(k),
              layout.state_size(k + 1)) = lin.B[k];
      H.block(layout.start[k + 1], layout.start[k], layout.state_size(k + 1),
              layout.state_size(k)) = lin.B[k].transpose();
    }
  }
  return H;
}

void ExpectSameLinearization(Chain& c) {
  const std::optional<ChainLayout> layout = MakeChainLayout(*c.problem, c.states);
  ASSERT_TRUE(layout);
  const std::optional<ChainLinearization> lin = LinearizeChain(*c.problem, *layout);
  ASSERT_TRUE(lin);
  const Reference ref = Evaluate(c);
  EXPECT_NEAR(lin->cost, ref.cost, 1e-9 * ref.cost);
  EXPECT_LT((lin->gradient - ref.gradient).norm(), 1e-9 * ref.gradient.norm());
  const Eigen::MatrixXd H = Dense(*lin, *layout);
  EXPECT_LT((H - ref.H).norm(), 1e-9 * ref.H.norm());
  EXPECT_NEAR(*ChainCost(*c.problem), ref.cost, 1e-9 * ref.cost);
}

TEST(LinearizeChain, MatchesCeresWithoutALoss) {
  Chain c = MakeChain(8, nullptr);
  ExpectSameLinearization(c);
}

TEST(LinearizeChain, MatchesCeresWithARobustLossOfNegativeCurvature) {
  // Cauchy: rho'' < 0 everywhere, the corrector's plain sqrt(rho') scaling.
  Chain c = MakeChain(8, [] { return new ceres::CauchyLoss(1.0); });
  ExpectSameLinearization(c);
}

TEST(LinearizeChain, MatchesCeresWithALossOfPositiveCurvature) {
  // Tolerant loss: rho'' > 0, the corrector's alpha branch (the Jacobian's rank-one correction).
  Chain c = MakeChain(8, [] { return new ceres::TolerantLoss(2.0, 1.0); });
  ExpectSameLinearization(c);
}

TEST(SolveChain, ReachesCeresMinimum) {
  for (const bool robust : {false, true}) {
    auto loss =
        robust ? std::function<ceres::LossFunction*()>([] { return new ceres::HuberLoss(1.0); })
               : std::function<ceres::LossFunction*()>();
    Chain ours = MakeChain(12, loss);
    Chain theirs = MakeChain(12, loss);
    ChainSolverOptions options;
    options.function_tolerance = 1e-14;
    options.gradient_tolerance = 1e-12;
    options.parameter_tolerance = 1e-14;
    const std::optional<ChainSolverSummary> summary =
        SolveChain(ours.problem.get(), ours.states, options);
    ASSERT_TRUE(summary);
    EXPECT_TRUE(summary->usable);
    EXPECT_LT(summary->final_cost, summary->initial_cost);
    EXPECT_GT(summary->successful_steps, 1);

    ceres::Solver::Options ceres_options;
    ceres_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    ceres_options.function_tolerance = 1e-14;
    ceres_options.gradient_tolerance = 1e-12;
    ceres_options.parameter_tolerance = 1e-14;
    ceres_options.max_num_iterations = 200;
    ceres::Solver::Summary ceres_summary;
    ceres::Solve(ceres_options, theirs.problem.get(), &ceres_summary);
    EXPECT_NEAR(summary->final_cost, ceres_summary.final_cost, 1e-8 * ceres_summary.final_cost)
        << (robust ? "Huber" : "no loss");
    for (int k = 0; k < 12; ++k) {
      EXPECT_NEAR(ours.p[k][0], theirs.p[k][0], 1e-7);
      EXPECT_NEAR(ours.p[k][1], theirs.p[k][1], 1e-7);
      const Eigen::Quaterniond a(ours.q[k][3], ours.q[k][0], ours.q[k][1], ours.q[k][2]);
      const Eigen::Quaterniond b(theirs.q[k][3], theirs.q[k][0], theirs.q[k][1], theirs.q[k][2]);
      EXPECT_LT(a.angularDistance(b), 1e-7);
    }
  }
}

TEST(SolveChain, AProblemThatIsNotAChainIsLeftUntouched) {
  Chain c = MakeChain(5, nullptr);
  // A factor joining states 0 and 2.
  c.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<MotionResidual, 5, 2, 4, 2, 4>(
                                  new MotionResidual(0.4, 0.0, 0.2)),
                              nullptr, c.p[0].data(), c.q[0].data(), c.p[2].data(), c.q[2].data());
  const auto before = c.p;
  EXPECT_FALSE(SolveChain(c.problem.get(), c.states));
  EXPECT_EQ(c.p, before);

  // A block outside the states.
  Chain d = MakeChain(5, nullptr);
  std::vector<std::vector<double*>> fewer(d.states.begin(), d.states.end() - 1);
  EXPECT_FALSE(SolveChain(d.problem.get(), fewer));
  // A state's block held constant.
  Chain e = MakeChain(5, nullptr);
  e.problem->SetParameterBlockConstant(e.p[1].data());
  EXPECT_FALSE(SolveChain(e.problem.get(), e.states));
}

TEST(SolveChain, StopsOnTheAbsoluteCostChangeAndTheIterationLimit) {
  Chain a = MakeChain(8, nullptr);
  ChainSolverOptions options;
  options.cost_change_tolerance = 1e12;  // any kept step is small enough
  const auto one = SolveChain(a.problem.get(), a.states, options);
  ASSERT_TRUE(one);
  EXPECT_EQ(one->successful_steps, 1);
  EXPECT_EQ(one->termination, "cost change below tolerance");

  Chain b = MakeChain(8, nullptr);
  options = ChainSolverOptions();
  options.max_iterations = 2;
  options.function_tolerance = 0.0;
  const auto two = SolveChain(b.problem.get(), b.states, options);
  ASSERT_TRUE(two);
  EXPECT_EQ(two->iterations, 2);
  EXPECT_EQ(two->termination, "maximum number of iterations");
}

TEST(SolveChain, RefusesOptionsOutOfRange) {
  Chain c = MakeChain(3, nullptr);
  ChainSolverOptions options;
  options.initial_lambda = 0.0;
  EXPECT_THROW(SolveChain(c.problem.get(), c.states, options), std::invalid_argument);
  options = ChainSolverOptions();
  options.max_iterations = -1;
  EXPECT_THROW(SolveChain(c.problem.get(), c.states, options), std::invalid_argument);
  double stray[2] = {0.0, 0.0};
  EXPECT_THROW(SolveChain(c.problem.get(), {{stray}}), std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
