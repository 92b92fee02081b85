#include "auvdock/estimator/marginal_covariance.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <ceres/crs_matrix.h>

namespace auvdock {
namespace {

void SetReason(std::string* reason, const std::string& text) {
  if (reason != nullptr) *reason = text;
}

}  // namespace

std::optional<Eigen::MatrixXd> MarginalCovariance(ceres::Problem* problem, const double* block,
                                                  const MarginalCovarianceOptions& options,
                                                  std::string* reason) {
  double* target = const_cast<double*>(block);  // Ceres' API takes non-const block pointers
  if (!problem->HasParameterBlock(target)) {
    throw std::invalid_argument("MarginalCovariance: the block is not in the problem");
  }
  if (problem->IsParameterBlockConstant(target)) {
    throw std::invalid_argument("MarginalCovariance: the block is held constant");
  }
  // Every variable block, the target first so that its columns are 0 .. size - 1.
  std::vector<double*> blocks;
  problem->GetParameterBlocks(&blocks);
  blocks.erase(std::remove_if(blocks.begin(), blocks.end(),
                              [&](double* b) {
                                return b == target || problem->IsParameterBlockConstant(b);
                              }),
               blocks.end());
  blocks.insert(blocks.begin(), target);
  const int size = problem->ParameterBlockTangentSize(target);

  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = blocks;
  evaluate.apply_loss_function = true;
  ceres::CRSMatrix crs;
  if (!problem->Evaluate(evaluate, nullptr, nullptr, nullptr, &crs)) {
    SetReason(reason, "the residuals could not be evaluated");
    return std::nullopt;
  }
  const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor, int>> J(
      crs.num_rows, crs.num_cols, static_cast<Eigen::Index>(crs.values.size()), crs.rows.data(),
      crs.cols.data(), crs.values.data());
  const Eigen::SparseMatrix<double> H = (J.transpose() * J).pruned();

  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(H);
  if (ldlt.info() != Eigen::Success) {
    SetReason(reason, "the information matrix could not be factored");
    return std::nullopt;
  }
  const Eigen::VectorXd& d = ldlt.vectorD();
  const double largest = d.size() > 0 ? d.cwiseAbs().maxCoeff() : 0.0;
  if (!(largest > 0.0) || d.minCoeff() <= options.min_relative_pivot * largest) {
    SetReason(reason, "rank-deficient information (an unobserved direction)");
    return std::nullopt;
  }
  const Eigen::MatrixXd unit = Eigen::MatrixXd::Identity(crs.num_cols, size);
  const Eigen::MatrixXd columns = ldlt.solve(unit);
  Eigen::MatrixXd sigma = columns.topRows(size);
  sigma = 0.5 * (sigma + sigma.transpose()).eval();
  if (!sigma.allFinite()) {
    SetReason(reason, "the covariance is not finite");
    return std::nullopt;
  }
  return sigma;
}

}  // namespace auvdock
