// A small pose graph for the marginalization and covariance tests: three poses (PoseManifold)
// chained by relative-pose residuals, an absolute prior on the first, and two Euclidean 3-vectors
// each tied to a pose by a body-frame residual. Every residual is autodiff with unit weights;
// the terms are kept so that a test can rebuild a dense reference Jacobian.
#pragma once

#include <memory>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ceres/cost_function.h>
#include <ceres/problem.h>

#include "factors/pose_manifold.h"

namespace auvdock::test {

struct SmallGraph {
  double pose[3][7];
  double vec[2][3];
  struct Term {
    ceres::CostFunction* cost;  // owned by the problem
    std::vector<double*> blocks;
  };
  std::vector<Term> terms;
};

// A rotation Exp(phi) with phi ~ N(0, sigma^2 I).
Eigen::Quaterniond RandomRotation(std::mt19937_64& rng, double sigma);

// Fills `g` with seeded random values and adds its residuals to `problem`, setting `manifold` on
// the poses. With with_prior = false the first pose has no absolute prior (a gauge freedom).
void BuildSmallGraph(SmallGraph* g, ceres::Problem* problem, const PoseManifold* manifold,
                     bool with_prior = true);

// Problem options under which the tests keep ownership of the manifold.
ceres::Problem::Options NonOwningManifolds();

// The terms' stacked Jacobian in the tangent space (ambient Jacobian times PlusJacobian for a
// pose), columns in the order of `order` (6 per pose, 3 per vector), and the stacked residual.
// Only terms touching a block of `only_touching` are stacked (all terms when it is empty).
void DenseTangentJacobian(const SmallGraph& g, const std::vector<double*>& order,
                          const PoseManifold& manifold, const std::vector<double*>& only_touching,
                          Eigen::MatrixXd* J, Eigen::VectorXd* r);

}  // namespace auvdock::test
