#include "tools/eval/hungarian.h"

#include <algorithm>
#include <limits>

namespace mbslam {
namespace eval {

std::vector<int> SolveAssignment(const Eigen::MatrixXd& cost, double* total_cost) {
  const int rows = static_cast<int>(cost.rows()), cols = static_cast<int>(cost.cols());
  std::vector<int> row_to_col(static_cast<size_t>(rows), -1);
  if (total_cost) {
    *total_cost = 0.0;
  }
  if (rows == 0 || cols == 0) {
    return row_to_col;
  }
  // Square problem of size n, padded with zero-cost dummy rows / columns. Indices are
  // 1-based below; index 0 is the virtual column from which each augmenting path starts.
  const int n = std::max(rows, cols);
  auto a = [&](int i, int j) { return (i <= rows && j <= cols) ? cost(i - 1, j - 1) : 0.0; };
  const double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> u(static_cast<size_t>(n) + 1, 0.0), v(static_cast<size_t>(n) + 1, 0.0);
  std::vector<int> match(static_cast<size_t>(n) + 1, 0);  // match[j] = row assigned to column j
  std::vector<int> way(static_cast<size_t>(n) + 1, 0);    // previous column on the shortest path
  for (int i = 1; i <= n; ++i) {
    // Grow a shortest augmenting path (reduced costs a - u - v >= 0) from row i.
    match[0] = i;
    int j0 = 0;
    std::vector<double> min_slack(static_cast<size_t>(n) + 1, kInf);
    std::vector<bool> used(static_cast<size_t>(n) + 1, false);
    do {
      used[static_cast<size_t>(j0)] = true;
      const int i0 = match[static_cast<size_t>(j0)];
      double delta = kInf;
      int j1 = 0;
      for (int j = 1; j <= n; ++j) {
        if (used[static_cast<size_t>(j)]) {
          continue;
        }
        const double reduced = a(i0, j) - u[static_cast<size_t>(i0)] - v[static_cast<size_t>(j)];
        if (reduced < min_slack[static_cast<size_t>(j)]) {
          min_slack[static_cast<size_t>(j)] = reduced;
          way[static_cast<size_t>(j)] = j0;
        }
        if (min_slack[static_cast<size_t>(j)] < delta) {
          delta = min_slack[static_cast<size_t>(j)];
          j1 = j;
        }
      }
      // Update the potentials so that the tree's edges stay tight.
      for (int j = 0; j <= n; ++j) {
        if (used[static_cast<size_t>(j)]) {
          u[static_cast<size_t>(match[static_cast<size_t>(j)])] += delta;
          v[static_cast<size_t>(j)] -= delta;
        } else {
          min_slack[static_cast<size_t>(j)] -= delta;
        }
      }
      j0 = j1;
    } while (match[static_cast<size_t>(j0)] != 0);
    // Flip the matching along the path.
    do {
      const int j1 = way[static_cast<size_t>(j0)];
      match[static_cast<size_t>(j0)] = match[static_cast<size_t>(j1)];
      j0 = j1;
    } while (j0 != 0);
  }
  for (int j = 1; j <= n; ++j) {
    const int i = match[static_cast<size_t>(j)];
    if (i >= 1 && i <= rows && j <= cols) {
      row_to_col[static_cast<size_t>(i - 1)] = j - 1;
      if (total_cost) {
        *total_cost += cost(i - 1, j - 1);
      }
    }
  }
  return row_to_col;
}

std::vector<int> SolveMaxAssignment(const Eigen::MatrixXd& weight, double* total_weight) {
  std::vector<int> assignment = SolveAssignment(-weight);
  if (total_weight) {
    *total_weight = 0.0;
    for (size_t i = 0; i < assignment.size(); ++i) {
      if (assignment[i] >= 0) {
        *total_weight += weight(static_cast<Eigen::Index>(i), assignment[i]);
      }
    }
  }
  return assignment;
}

}  // namespace eval
}  // namespace mbslam
