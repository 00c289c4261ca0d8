#include "tools/tracks/misclassification.h"

#include <algorithm>
#include <map>

#include <Eigen/Core>

#include "tools/eval/hungarian.h"

namespace mbslam {

std::vector<int> HungarianAssignment(const std::vector<std::vector<double>>& cost) {
  // The evaluation toolkit's solver (tools/eval/hungarian.h), on a dense copy.
  const Eigen::Index rows = static_cast<Eigen::Index>(cost.size());
  const Eigen::Index cols = rows > 0 ? static_cast<Eigen::Index>(cost[0].size()) : 0;
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (Eigen::Index c = 0; c < cols; ++c) m(r, c) = cost[static_cast<size_t>(r)][static_cast<size_t>(c)];
  }
  return eval::SolveAssignment(m);
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
