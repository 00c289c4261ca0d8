#ifndef MBSLAM_TOOLS_TRACKS_MISCLASSIFICATION_H_
#define MBSLAM_TOOLS_TRACKS_MISCLASSIFICATION_H_

#include <vector>

namespace mbslam {

// Fraction of items whose predicted group differs from the true one under the best
// one-to-one matching of predicted to true groups (Hungarian algorithm). Groups may
// differ in number; unmatched predicted groups count as wrong.
double Misclassification(const std::vector<int>& truth, const std::vector<int>& predicted);

// Minimum-cost assignment for a square cost matrix (row -> column).
std::vector<int> HungarianAssignment(const std::vector<std::vector<double>>& cost);

}  // namespace mbslam

#endif  // MBSLAM_TOOLS_TRACKS_MISCLASSIFICATION_H_
