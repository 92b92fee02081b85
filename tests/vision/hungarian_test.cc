#include "auvdock/vision/hungarian.h"

#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

namespace auvdock {
namespace {

// Best assignment by exhaustive search, ranked as the solver ranks them: most assigned rows
// first, then lowest total cost.
struct BruteForceBest {
  int assigned = -1;
  double cost = 0.0;
};

void Search(const Eigen::MatrixXd& cost, int row, std::vector<char>* used, int assigned,
            double total, BruteForceBest* best) {
  if (row == cost.rows()) {
    if (assigned > best->assigned || (assigned == best->assigned && total < best->cost)) {
      best->assigned = assigned;
      best->cost = total;
    }
    return;
  }
  Search(cost, row + 1, used, assigned, total, best);  // leave the row unassigned
  for (int j = 0; j < cost.cols(); ++j) {
    if ((*used)[j] || !std::isfinite(cost(row, j))) continue;
    (*used)[j] = 1;
    Search(cost, row + 1, used, assigned + 1, total + cost(row, j), best);
    (*used)[j] = 0;
  }
}

BruteForceBest BruteForce(const Eigen::MatrixXd& cost) {
  BruteForceBest best;
  std::vector<char> used(cost.cols(), 0);
  Search(cost, 0, &used, 0, 0.0, &best);
  return best;
}

// Checks that `assignment` is a valid partial assignment and returns its size and cost.
BruteForceBest Evaluate(const Eigen::MatrixXd& cost, const std::vector<int>& assignment) {
  EXPECT_EQ(static_cast<int>(assignment.size()), cost.rows());
  std::vector<char> used(cost.cols(), 0);
  BruteForceBest result{0, 0.0};
  for (int i = 0; i < static_cast<int>(assignment.size()); ++i) {
    const int j = assignment[i];
    if (j < 0) continue;
    EXPECT_LT(j, cost.cols());
    EXPECT_FALSE(used[j]) << "column " << j << " used twice";
    used[j] = 1;
    EXPECT_TRUE(std::isfinite(cost(i, j))) << "forbidden pair " << i << "," << j;
    ++result.assigned;
    result.cost += cost(i, j);
  }
  return result;
}

TEST(Hungarian, HandWorkedSquare) {
  Eigen::MatrixXd cost(3, 3);
  cost << 4, 1, 3,  //
      2, 0, 5,      //
      3, 2, 2;
  // Optimum: row 0 -> 1, row 1 -> 0, row 2 -> 2, total 1 + 2 + 2 = 5.
  EXPECT_EQ(SolveAssignment(cost), (std::vector<int>{1, 0, 2}));
}

TEST(Hungarian, MoreRowsThanColumnsLeavesRowsUnassigned) {
  Eigen::MatrixXd cost(3, 2);
  cost << 1, 9,  //
      9, 1,      //
      1.5, 1.5;
  // Only two rows fit; rows 0 and 1 take 1 + 1 = 2, cheaper than any pair with row 2 (>= 2.5).
  EXPECT_EQ(SolveAssignment(cost), (std::vector<int>{0, 1, -1}));
}

TEST(Hungarian, ForbiddenEntriesAndFullyForbiddenRow) {
  const double kX = kForbiddenCost;
  Eigen::MatrixXd cost(3, 3);
  cost << 1, kX, kX,  //
      kX, kX, kX,     //
      0, 5, kX;
  // Row 1 has no option; rows 0 and 2 must not both take column 0.
  EXPECT_EQ(SolveAssignment(cost), (std::vector<int>{0, -1, 1}));
}

TEST(Hungarian, MaximisesTheNumberOfAllowedPairsBeforeCost) {
  const double kX = kForbiddenCost;
  Eigen::MatrixXd cost(2, 2);
  cost << 0, 100,  //
      0, kX;
  // Taking (0,0) alone would be cheaper, but (0,1) + (1,0) assigns both rows.
  EXPECT_EQ(SolveAssignment(cost), (std::vector<int>{1, 0}));
}

TEST(Hungarian, EmptyAndAllForbidden) {
  EXPECT_TRUE(SolveAssignment(Eigen::MatrixXd(0, 3)).empty());
  EXPECT_EQ(SolveAssignment(Eigen::MatrixXd(2, 0)), (std::vector<int>{-1, -1}));
  Eigen::MatrixXd all_forbidden = Eigen::MatrixXd::Constant(2, 3, kForbiddenCost);
  EXPECT_EQ(SolveAssignment(all_forbidden), (std::vector<int>{-1, -1}));
}

TEST(Hungarian, MatchesBruteForceOnRandomMatrices) {
  std::mt19937_64 rng(20240611);
  std::uniform_int_distribution<int> size(1, 6);
  std::uniform_real_distribution<double> value(-5.0, 20.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int trials = 0;
  int with_forbidden = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const int rows = size(rng);
    const int cols = size(rng);
    // A third of the trials have no forbidden entries, the others up to 60 % of them.
    const double forbidden_fraction = trial % 3 == 0 ? 0.0 : 0.6 * unit(rng);
    // Integer-valued costs in some trials to create ties.
    const bool integer = trial % 4 == 1;
    Eigen::MatrixXd cost(rows, cols);
    bool any_forbidden = false;
    for (int i = 0; i < rows; ++i) {
      for (int j = 0; j < cols; ++j) {
        if (unit(rng) < forbidden_fraction) {
          cost(i, j) = kForbiddenCost;
          any_forbidden = true;
        } else {
          cost(i, j) = integer ? std::round(value(rng) / 5.0) : value(rng);
        }
      }
    }
    const BruteForceBest expected = BruteForce(cost);
    const BruteForceBest got = Evaluate(cost, SolveAssignment(cost));
    ASSERT_EQ(got.assigned, expected.assigned) << "trial " << trial << "\n" << cost;
    ASSERT_NEAR(got.cost, expected.cost, 1e-9) << "trial " << trial << "\n" << cost;
    ++trials;
    with_forbidden += any_forbidden;
  }
  std::printf(
      "hungarian: %d random matrices up to 6x6 (%d with forbidden pairs) match brute force\n",
      trials, with_forbidden);
}

TEST(Hungarian, LargeSquareMatrixIsAPermutation) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> value(0.0, 1.0);
  const int n = 60;
  Eigen::MatrixXd cost(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) cost(i, j) = value(rng);
  }
  // A planted zero-cost permutation must be found exactly.
  std::vector<int> planted(n);
  for (int i = 0; i < n; ++i) planted[i] = (7 * i + 3) % n;
  for (int i = 0; i < n; ++i) cost(i, planted[i]) = 0.0;
  EXPECT_EQ(SolveAssignment(cost), planted);
}

}  // namespace
}  // namespace auvdock
