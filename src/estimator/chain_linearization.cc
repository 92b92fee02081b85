#include "auvdock/estimator/chain_linearization.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include "factors/tangent_jacobians.h"

namespace auvdock {
namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Applies a robust loss to one block's residual and tangent Jacobian (nullptr: none) as Ceres'
// corrector does (header); returns the block's cost 1/2 rho(s).
double ApplyLoss(const ceres::LossFunction* loss, Eigen::VectorXd* r, Eigen::MatrixXd* J) {
  const double s = r->squaredNorm();
  if (loss == nullptr) return 0.5 * s;
  double rho[3];
  loss->Evaluate(s, rho);
  const double sqrt_rho1 = std::sqrt(std::max(0.0, rho[1]));
  double residual_scale = sqrt_rho1;
  double alpha_over_s = 0.0;
  if (s > 0.0 && rho[2] > 0.0 && rho[1] > 0.0) {
    const double alpha = 1.0 - std::sqrt(1.0 + 2.0 * s * rho[2] / rho[1]);
    residual_scale = sqrt_rho1 / (1.0 - alpha);
    alpha_over_s = alpha / s;
  }
  if (J != nullptr && alpha_over_s != 0.0) {
    *J = sqrt_rho1 * (*J - alpha_over_s * (*r) * (r->transpose() * *J));
  } else if (J != nullptr) {
    *J *= sqrt_rho1;
  }
  *r *= residual_scale;
  return 0.5 * rho[0];
}

}  // namespace

std::optional<ChainLayout> MakeChainLayout(const ceres::Problem& problem,
                                           const std::vector<std::vector<double*>>& states) {
  const int n = static_cast<int>(states.size());
  ChainLayout layout;
  layout.start.assign(n + 1, 0);
  int num_blocks = 0;
  for (int k = 0; k < n; ++k) {
    int offset = 0;
    for (double* block : states[k]) {
      if (!problem.HasParameterBlock(block)) {
        throw std::invalid_argument("MakeChainLayout: a block is not in the problem");
      }
      if (problem.IsParameterBlockConstant(block)) return std::nullopt;
      ChainLayout::Block info;
      info.state = k;
      info.offset = offset;
      info.tangent = problem.ParameterBlockTangentSize(block);
      info.ambient = problem.ParameterBlockSize(block);
      info.manifold = problem.GetManifold(block);
      if (!layout.blocks.emplace(block, info).second) return std::nullopt;  // listed twice
      offset += info.tangent;
      ++num_blocks;
    }
    layout.start[k + 1] = layout.start[k] + offset;
  }
  if (num_blocks != problem.NumParameterBlocks()) return std::nullopt;
  return layout;
}

std::optional<ChainLinearization> LinearizeChain(const ceres::Problem& problem,
                                                 const ChainLayout& layout) {
  const int n = layout.num_states();
  ChainLinearization lin;
  lin.gradient = Eigen::VectorXd::Zero(layout.start[n]);
  lin.D.resize(n);
  lin.B.resize(n > 0 ? n - 1 : 0);
  lin.joined.assign(n > 0 ? n - 1 : 0, false);
  for (int k = 0; k < n; ++k) {
    lin.D[k] = Eigen::MatrixXd::Zero(layout.state_size(k), layout.state_size(k));
    if (k + 1 < n) lin.B[k] = Eigen::MatrixXd::Zero(layout.state_size(k), layout.state_size(k + 1));
  }
  // A block's dPlus/ddelta at its current value (ambient x tangent), computed when a cost
  // function without tangent-space Jacobians first needs it (a prior on a pose), then kept.
  std::unordered_map<const double*, RowMajorMatrix> plus_jacobians;
  const auto plus_jacobian = [&](const double* block,
                                 const ChainLayout::Block& info) -> const RowMajorMatrix* {
    auto it = plus_jacobians.find(block);
    if (it == plus_jacobians.end()) {
      RowMajorMatrix P(info.ambient, info.tangent);
      if (!info.manifold->PlusJacobian(block, P.data())) return nullptr;
      it = plus_jacobians.emplace(block, std::move(P)).first;
    }
    return &it->second;
  };

  std::vector<ceres::ResidualBlockId> ids;
  problem.GetResidualBlocks(&ids);
  std::vector<double*> parameters;
  std::vector<RowMajorMatrix> ambient;
  std::vector<double*> ambient_pointers;
  std::vector<const ChainLayout::Block*> infos;
  Eigen::VectorXd r;
  Eigen::MatrixXd J, JtJ;
  for (const ceres::ResidualBlockId id : ids) {
    const ceres::CostFunction* cost = problem.GetCostFunctionForResidualBlock(id);
    problem.GetParameterBlocksForResidualBlock(id, &parameters);
    const int m = cost->num_residuals();
    const int p = static_cast<int>(parameters.size());
    const auto* in_tangent_space = dynamic_cast<const TangentJacobians*>(cost);
    ambient.resize(p);
    ambient_pointers.resize(p);
    infos.resize(p);
    int k_min = n, k_max = -1;
    for (int i = 0; i < p; ++i) {
      const auto it = layout.blocks.find(parameters[i]);
      if (it == layout.blocks.end()) return std::nullopt;
      infos[i] = &it->second;
      k_min = std::min(k_min, infos[i]->state);
      k_max = std::max(k_max, infos[i]->state);
      ambient[i].resize(m, in_tangent_space != nullptr ? infos[i]->tangent : infos[i]->ambient);
      ambient_pointers[i] = ambient[i].data();
    }
    if (k_max - k_min > 1) return std::nullopt;  // not a chain
    r.resize(m);
    // The block's tangent Jacobian, all its parameter blocks side by side (J~ below): straight
    // from a cost function that gives it (tangent_jacobians.h), else its ambient Jacobian times
    // each block's PlusJacobian.
    int width = 0;
    for (int i = 0; i < p; ++i) width += infos[i]->tangent;
    J.resize(m, width);
    if (in_tangent_space != nullptr) {
      if (!in_tangent_space->EvaluateInTangentSpace(parameters.data(), r.data(),
                                                    ambient_pointers.data())) {
        return std::nullopt;
      }
    } else if (!cost->Evaluate(parameters.data(), r.data(), ambient_pointers.data())) {
      return std::nullopt;
    }
    for (int i = 0, column = 0; i < p; ++i) {
      auto Ji = J.middleCols(column, infos[i]->tangent);
      if (in_tangent_space != nullptr || infos[i]->manifold == nullptr) {
        Ji = ambient[i];
      } else {
        const RowMajorMatrix* P = plus_jacobian(parameters[i], *infos[i]);
        if (P == nullptr) return std::nullopt;
        Ji.noalias() = ambient[i].lazyProduct(*P);
      }
      column += infos[i]->tangent;
    }
    const double block_cost = ApplyLoss(problem.GetLossFunctionForResidualBlock(id), &r, &J);
    if (!std::isfinite(block_cost) || !r.allFinite() || !J.allFinite()) return std::nullopt;
    lin.cost += block_cost;
    // g += J~^T r~ and H += J~^T J~, scattered into the states' blocks (small: a lazy product
    // avoids the general matrix product's packing).
    if (m <= 4) {
      JtJ.noalias() = J.transpose().lazyProduct(J);  // a pixel pair or a point: no packing
    } else {
      JtJ.noalias() = J.transpose() * J;
    }
    for (int i = 0, ci = 0; i < p; ++i) {
      const ChainLayout::Block& a = *infos[i];
      lin.gradient.segment(layout.start[a.state] + a.offset, a.tangent).noalias() +=
          J.middleCols(ci, a.tangent).transpose() * r;
      for (int j = 0, cj = 0; j < p; ++j) {
        const ChainLayout::Block& b = *infos[j];
        if (a.state == b.state) {
          lin.D[a.state].block(a.offset, b.offset, a.tangent, b.tangent) +=
              JtJ.block(ci, cj, a.tangent, b.tangent);
        } else if (b.state == a.state + 1) {
          lin.B[a.state].block(a.offset, b.offset, a.tangent, b.tangent) +=
              JtJ.block(ci, cj, a.tangent, b.tangent);
          lin.joined[a.state] = true;
        }
        cj += b.tangent;
      }
      ci += a.tangent;
    }
  }
  return lin;
}

std::optional<double> ChainCost(const ceres::Problem& problem) {
  std::vector<ceres::ResidualBlockId> ids;
  problem.GetResidualBlocks(&ids);
  std::vector<double*> parameters;
  Eigen::VectorXd r;
  double total = 0.0;
  for (const ceres::ResidualBlockId id : ids) {
    const ceres::CostFunction* cost = problem.GetCostFunctionForResidualBlock(id);
    problem.GetParameterBlocksForResidualBlock(id, &parameters);
    r.resize(cost->num_residuals());
    if (!cost->Evaluate(parameters.data(), r.data(), nullptr)) return std::nullopt;
    const double block_cost = ApplyLoss(problem.GetLossFunctionForResidualBlock(id), &r, nullptr);
    if (!std::isfinite(block_cost)) return std::nullopt;
    total += block_cost;
  }
  return total;
}

}  // namespace auvdock
