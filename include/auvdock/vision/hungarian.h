// Rectangular linear assignment ("Hungarian" matching): assign the rows of a cost matrix to its
// columns, each column to at most one row, at minimum total cost.
//
// Math: Kuhn-Munkres with dual potentials, organised as successive shortest augmenting paths
// (Jonker & Volgenant, "A shortest augmenting path algorithm for dense and sparse linear
// assignment problems", Computing 38, 1987). Rows are inserted one at a time; a Dijkstra search
// over the reduced costs c(i, j) - u(i) - v(j) >= 0 finds the cheapest way to give the new row a
// column (possibly moving earlier rows), then the potentials u, v are raised so that the reduced
// costs stay non-negative. O(r^2 c) for r <= c; a matrix with more rows than columns is solved
// transposed, so the cost is O(min^2 max).
//
// Forbidden pairs are +infinity entries (kForbiddenCost). With forbidden pairs a complete
// assignment may not exist; the solver then maximises the number of assigned rows first and
// minimises the total cost among the assignments of that size. It does so by replacing every
// forbidden entry with a penalty larger than any possible total of finite costs and dropping the
// penalised pairs afterwards. A row whose every option is forbidden is never assigned.
//
// Units: whatever the costs are (pixels for the light matchers). Costs may be negative; NaN and
// -infinity are programmer errors (asserted).
#pragma once

#include <limits>
#include <vector>

#include <Eigen/Core>

namespace auvdock {

inline constexpr double kForbiddenCost = std::numeric_limits<double>::infinity();

// For each row of `cost`, the assigned column, or -1 when the row is left unassigned (more rows
// than columns, or no allowed column left for it).
std::vector<int> SolveAssignment(const Eigen::MatrixXd& cost);

}  // namespace auvdock
