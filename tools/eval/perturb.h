#ifndef MBSLAM_TOOLS_EVAL_PERTURB_H_
#define MBSLAM_TOOLS_EVAL_PERTURB_H_

// Inputs with known answers, for checking the evaluation code itself.
//
// Trajectories: est = S^-1 (gt + n), a known similarity S applied to ground truth with
// known position noise n. With `exact`, n is made orthogonal to every change a
// similarity can make (zero mean, no rotational moment, and the scale moment that makes
// S the exact optimum of Umeyama's cost), so the Sim(3)-aligned ATE equals the RMS of n
// exactly and the recovered alignment equals S.
//
// Labels: a known number of wrong labels, under a permutation of the label values, or
// a known split / merge of groups.

#include <cstdint>
#include <vector>

#include "common/util/status.h"
#include "services/perception/geometry/rigid3.h"
#include "tools/eval/trajectory.h"

namespace mbslam {
namespace eval {

struct TrajectoryPerturbation {
  Sim3d gt_from_est;           // the similarity S (est = S^-1 (gt + n))
  double noise_sigma_m = 0.0;  // standard deviation of the position noise per axis (m, truth units)
  uint64_t seed = 1;
  bool exact = true;  // make the noise orthogonal to the alignment (see above)
};

// `expected_ate_m`: the RMS of the injected noise (truth units), which is the Sim(3) ATE
// exactly when `exact` is set.
Status PerturbTrajectory(const Trajectory& gt, const TrajectoryPerturbation& p, Trajectory* est,
                         double* expected_ate_m);

struct LabelPerturbation {
  int wrong = 0;                // points moved to another (existing) group
  int split = 0;                // points of the largest group given a new label
  bool merge_smallest = false;  // the two smallest groups get one label
  bool permute = true;          // relabel the groups with shuffled, shifted values
  uint64_t seed = 1;
};

// `expected_errors`: the misclassification count the perturbation must produce. Fails
// when the request could change which matching is optimal (too many errors for the
// group sizes).
Status PerturbLabels(const std::vector<int>& truth, const LabelPerturbation& p,
                     std::vector<int>* predicted, int* expected_errors);

}  // namespace eval
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_EVAL_PERTURB_H_
