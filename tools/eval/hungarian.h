#ifndef MBSLAM_TOOLS_EVAL_HUNGARIAN_H_
#define MBSLAM_TOOLS_EVAL_HUNGARIAN_H_

// Minimum-cost assignment (Hungarian / Kuhn-Munkres with potentials, O(n^3)) for
// rectangular cost matrices: every row is assigned to a distinct column or, when there
// are more rows than columns, left unassigned (and vice versa).

#include <Eigen/Core>

#include <vector>

namespace mbslam {
namespace eval {

// Returns, for each row, its column or -1. `total_cost` (optional) gets the summed cost
// of the assigned pairs. Costs must be finite.
std::vector<int> SolveAssignment(const Eigen::MatrixXd& cost, double* total_cost = nullptr);

// The same for a maximum-weight assignment.
std::vector<int> SolveMaxAssignment(const Eigen::MatrixXd& weight, double* total_weight = nullptr);

}  // namespace eval
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_EVAL_HUNGARIAN_H_
