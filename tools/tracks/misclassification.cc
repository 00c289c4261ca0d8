#include "tools/tracks/misclassification.h"

#include <algorithm>
#include <limits>
#include <map>

namespace mbslam {

std::vector<int> HungarianAssignment(const std::vector<std::vector<double>>& cost) {
  // Kuhn-Munkres with potentials, O(n^3); 1-based internal indexing.
  const int n = static_cast<int>(cost.size());
  const double inf = std::numeric_limits<double>::max() / 4;
  std::vector<double> u(n + 1, 0.0), v(n + 1, 0.0);
  std::vector<int> p(n + 1, 0), way(n + 1, 0);
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::vector<double> minv(n + 1, inf);
    std::vector<bool> used(n + 1, false);
    do {
      used[j0] = true;
      const int i0 = p[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= n; ++j) {
        if (used[j]) continue;
        const double cur = cost[i0 - 1][j - 1] - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= n; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0);
  }
  std::vector<int> assignment(n, -1);
  for (int j = 1; j <= n; ++j) {
    if (p[j] > 0) assignment[p[j] - 1] = j - 1;
  }
  return assignment;
}

double Misclassification(const std::vector<int>& truth, const std::vector<int>& predicted) {
  if (truth.empty()) return 0.0;
  std::map<int, int> ti, pi;
  for (int t : truth) ti.emplace(t, static_cast<int>(ti.size()));
  for (int p : predicted) pi.emplace(p, static_cast<int>(pi.size()));
  const int n = static_cast<int>(std::max(ti.size(), pi.size()));
  std::vector<std::vector<double>> overlap(n, std::vector<double>(n, 0.0));
  for (size_t i = 0; i < truth.size(); ++i) overlap[pi[predicted[i]]][ti[truth[i]]] += 1.0;
  // Maximise overlap = minimise negative overlap.
  std::vector<std::vector<double>> cost(n, std::vector<double>(n, 0.0));
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) cost[r][c] = -overlap[r][c];
  }
  const std::vector<int> a = HungarianAssignment(cost);
  double matched = 0.0;
  for (int r = 0; r < n; ++r) matched += overlap[r][a[r]];
  return 1.0 - matched / static_cast<double>(truth.size());
}

}  // namespace mbslam
