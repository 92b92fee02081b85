#include "auvdock/vision/hungarian.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace auvdock {

namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Shortest augmenting paths for a finite matrix with rows <= cols. Returns the column of each row.
// Column index `cols` is a virtual column that holds the row being inserted.
std::vector<int> SolveWide(const RowMajorMatrix& a) {
  const int rows = static_cast<int>(a.rows());
  const int cols = static_cast<int>(a.cols());
  const double kInf = std::numeric_limits<double>::infinity();
  const int virtual_col = cols;

  std::vector<double> u(rows, 0.0);           // row potentials
  std::vector<double> v(cols + 1, 0.0);       // column potentials
  std::vector<int> row_of_col(cols + 1, -1);  // current matching, by column
  std::vector<int> previous_col(cols + 1, virtual_col);
  std::vector<double> distance(cols + 1);
  std::vector<char> settled(cols + 1);

  for (int new_row = 0; new_row < rows; ++new_row) {
    row_of_col[virtual_col] = new_row;
    int col = virtual_col;
    std::fill(distance.begin(), distance.end(), kInf);
    std::fill(settled.begin(), settled.end(), 0);
    // Dijkstra over columns: grow the tree of settled columns until a free column is reached.
    do {
      settled[col] = 1;
      const int row = row_of_col[col];
      double delta = kInf;
      int next_col = -1;
      for (int j = 0; j < cols; ++j) {
        if (settled[j]) continue;
        const double reduced = a(row, j) - u[row] - v[j];
        if (reduced < distance[j]) {
          distance[j] = reduced;
          previous_col[j] = col;
        }
        if (distance[j] < delta) {
          delta = distance[j];
          next_col = j;
        }
      }
      assert(next_col >= 0);
      // Raise the potentials of the tree by delta: reduced costs stay >= 0, the tight edge to
      // next_col becomes zero.
      for (int j = 0; j <= cols; ++j) {
        if (settled[j]) {
          u[row_of_col[j]] += delta;
          v[j] -= delta;
        } else {
          distance[j] -= delta;
        }
      }
      col = next_col;
    } while (row_of_col[col] != -1);
    // Augment: shift the rows along the path back to the virtual column.
    while (col != virtual_col) {
      const int previous = previous_col[col];
      row_of_col[col] = row_of_col[previous];
      col = previous;
    }
  }

  std::vector<int> col_of_row(rows, -1);
  for (int j = 0; j < cols; ++j) {
    if (row_of_col[j] >= 0) col_of_row[row_of_col[j]] = j;
  }
  return col_of_row;
}

}  // namespace

std::vector<int> SolveAssignment(const Eigen::MatrixXd& cost) {
  const int rows = static_cast<int>(cost.rows());
  const int cols = static_cast<int>(cost.cols());
  std::vector<int> assignment(rows, -1);
  if (rows == 0 || cols == 0) return assignment;

  double lowest = std::numeric_limits<double>::infinity();
  double highest = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < cols; ++j) {
      const double c = cost(i, j);
      assert(!std::isnan(c) && c != -std::numeric_limits<double>::infinity());
      if (std::isfinite(c)) {
        lowest = std::min(lowest, c);
        highest = std::max(highest, c);
      }
    }
  }
  if (!std::isfinite(lowest)) return assignment;  // everything forbidden

  // Finite costs shifted to [0, range]; a forbidden pair costs more than any complete set of
  // finite pairs, so one more allowed pair always beats any saving on the others.
  const int size = std::min(rows, cols);
  const double range = highest - lowest;
  const double penalty = (range + 1.0) * (size + 1);

  const bool transposed = rows > cols;
  RowMajorMatrix work(transposed ? cols : rows, transposed ? rows : cols);
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < cols; ++j) {
      const double c = cost(i, j);
      const double shifted = std::isfinite(c) ? c - lowest : penalty;
      if (transposed) {
        work(j, i) = shifted;
      } else {
        work(i, j) = shifted;
      }
    }
  }

  const std::vector<int> work_assignment = SolveWide(work);
  for (int w = 0; w < static_cast<int>(work_assignment.size()); ++w) {
    const int other = work_assignment[w];
    if (other < 0) continue;
    const int row = transposed ? other : w;
    const int col = transposed ? w : other;
    if (std::isfinite(cost(row, col))) assignment[row] = col;
  }
  return assignment;
}

}  // namespace auvdock
