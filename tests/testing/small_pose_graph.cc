#include "tests/testing/small_pose_graph.h"

#include <algorithm>

#include <ceres/autodiff_cost_function.h>

namespace auvdock::test {
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

}  // namespace

Eigen::Quaterniond RandomRotation(std::mt19937_64& rng, double sigma) {
  std::normal_distribution<double> n(0.0, sigma);
  return QuaternionExp<double>(Eigen::Vector3d(n(rng), n(rng), n(rng)));
}

void BuildSmallGraph(SmallGraph* g, ceres::Problem* problem, const PoseManifold* manifold,
                     bool with_prior) {
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
  if (with_prior) {
    add(new ceres::AutoDiffCostFunction<PosePriorCost, 6, 7>(new PosePriorCost), {g->pose[0]});
  }
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

void DenseTangentJacobian(const SmallGraph& g, const std::vector<double*>& order,
                          const PoseManifold& manifold, const std::vector<double*>& only_touching,
                          Eigen::MatrixXd* J, Eigen::VectorXd* r) {
  auto is_vector = [&](const double* block) { return block == g.vec[0] || block == g.vec[1]; };
  std::vector<int> column(order.size());
  int n = 0;
  for (size_t i = 0; i < order.size(); ++i) {
    column[i] = n;
    n += is_vector(order[i]) ? 3 : 6;
  }
  std::vector<Eigen::MatrixXd> rows;
  std::vector<Eigen::VectorXd> residuals;
  for (const SmallGraph::Term& term : g.terms) {
    const bool touches =
        only_touching.empty() ||
        std::any_of(term.blocks.begin(), term.blocks.end(), [&](double* b) {
          return std::find(only_touching.begin(), only_touching.end(), b) != only_touching.end();
        });
    if (!touches) continue;
    const int m = term.cost->num_residuals();
    Eigen::VectorXd term_r(m);
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    std::vector<RowMajor> J_ambient;
    std::vector<double*> jacobian_ptrs;
    for (double* block : term.blocks) J_ambient.emplace_back(m, is_vector(block) ? 3 : 7);
    for (auto& J_block : J_ambient) jacobian_ptrs.push_back(J_block.data());
    std::vector<const double*> params(term.blocks.begin(), term.blocks.end());
    term.cost->Evaluate(params.data(), term_r.data(), jacobian_ptrs.data());
    Eigen::MatrixXd J_term = Eigen::MatrixXd::Zero(m, n);
    for (size_t i = 0; i < term.blocks.size(); ++i) {
      const auto it = std::find(order.begin(), order.end(), term.blocks[i]);
      if (it == order.end()) continue;
      const int col = column[it - order.begin()];
      if (is_vector(term.blocks[i])) {
        J_term.middleCols(col, 3) = J_ambient[i];
      } else {
        Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus;
        manifold.PlusJacobian(term.blocks[i], plus.data());
        J_term.middleCols(col, 6) = J_ambient[i] * plus;
      }
    }
    rows.push_back(J_term);
    residuals.push_back(term_r);
  }
  int m_total = 0;
  for (const auto& R : rows) m_total += static_cast<int>(R.rows());
  J->setZero(m_total, n);
  r->setZero(m_total);
  int row = 0;
  for (size_t k = 0; k < rows.size(); ++k) {
    J->middleRows(row, rows[k].rows()) = rows[k];
    r->segment(row, rows[k].rows()) = residuals[k];
    row += static_cast<int>(rows[k].rows());
  }
}

}  // namespace auvdock::test
