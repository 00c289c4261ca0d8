#include "tools/eval/perturb.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <random>

namespace mbslam {
namespace eval {

Status PerturbTrajectory(const Trajectory& gt, const TrajectoryPerturbation& p, Trajectory* est,
                         double* expected_ate_m) {
  const size_t n = gt.size();
  if (n < 3) {
    return Status::Error("perturb: needs at least 3 poses");
  }
  std::mt19937_64 rng(p.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd noise(3 * static_cast<Eigen::Index>(n));
  for (Eigen::Index i = 0; i < noise.size(); ++i) {
    noise(i) = p.noise_sigma_m * normal(rng);
  }

  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& g : gt) {
    mean += g.pose.translation;
  }
  mean /= static_cast<double>(n);
  if (p.exact && p.noise_sigma_m > 0.0) {
    // Remove every component a similarity could explain: translations (3), rotations
    // about the centroid (3) and scaling about it (1).
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(3 * static_cast<Eigen::Index>(n), 7);
    Eigen::VectorXd d(3 * static_cast<Eigen::Index>(n));
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Index r = 3 * static_cast<Eigen::Index>(i);
      const Eigen::Vector3d di = gt[i].pose.translation - mean;
      B.block<3, 3>(r, 0) = Eigen::Matrix3d::Identity();
      B.block<3, 3>(r, 3) = -Hat(di);  // column a: a x d_i
      B.block<3, 1>(r, 6) = di;
      d.segment<3>(r) = di;
    }
    const Eigen::VectorXd coeffs = B.colPivHouseholderQr().solve(noise);
    noise -= B * coeffs;
    // Put back the one scaling component that makes S the exact optimum:
    // sum n.d + sum |n|^2 = 0 with n = n_perp + alpha d  =>  alpha^2 + alpha + P/D = 0.
    const double P = noise.squaredNorm(), D = d.squaredNorm();
    if (!(D > 0.0) || 4.0 * P >= D) {
      return Status::Error("perturb: noise too large for the extent of the trajectory");
    }
    const double alpha = 0.5 * (-1.0 + std::sqrt(1.0 - 4.0 * P / D));
    noise += alpha * d;
  }
  *expected_ate_m = std::sqrt(noise.squaredNorm() / static_cast<double>(n));
  const Sim3d est_from_gt = p.gt_from_est.Inverse();
  est->clear();
  for (size_t i = 0; i < n; ++i) {
    Rigid3d noisy = gt[i].pose;
    noisy.translation += noise.segment<3>(3 * static_cast<Eigen::Index>(i));
    est->push_back({gt[i].utime, est_from_gt * noisy});
  }
  return Status::Ok();
}

Status PerturbLabels(const std::vector<int>& truth, const LabelPerturbation& p,
                     std::vector<int>* predicted, int* expected_errors) {
  std::mt19937_64 rng(p.seed);
  std::map<int, std::vector<size_t>> groups;
  for (size_t i = 0; i < truth.size(); ++i) {
    groups[truth[i]].push_back(i);
  }
  if (groups.size() < 2 && (p.wrong > 0 || p.merge_smallest)) {
    return Status::Error("perturb labels: needs at least 2 groups");
  }
  std::vector<int> order;  // group labels, smallest group first
  for (const auto& g : groups) {
    order.push_back(g.first);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return groups[a].size() < groups[b].size(); });
  *predicted = truth;
  int errors = 0;
  std::vector<bool> locked(truth.size(), false);  // points already changed or in a merged group
  std::vector<int> movable_groups(order.begin(), order.end());
  int merged_into = -1;
  if (p.merge_smallest) {
    if (groups.size() < 3) {
      return Status::Error("perturb labels: merging needs at least 3 groups");
    }
    const int small = order[0], other = order[1];
    for (size_t i : groups[small]) {
      (*predicted)[i] = other;
    }
    for (size_t i : groups[small]) {
      locked[i] = true;
    }
    for (size_t i : groups[other]) {
      locked[i] = true;
    }
    errors += static_cast<int>(groups[small].size());
    merged_into = other;
    movable_groups.erase(movable_groups.begin(), movable_groups.begin() + 2);
  }
  int split_label = -1;
  if (p.split > 0) {
    const int big = order.back();
    if (big == merged_into || 2 * p.split >= static_cast<int>(groups[big].size())) {
      return Status::Error("perturb labels: split too large for the largest group");
    }
    split_label = *std::max_element(truth.begin(), truth.end()) + 1;
    std::vector<size_t> members = groups[big];
    std::shuffle(members.begin(), members.end(), rng);
    for (int k = 0; k < p.split; ++k) {
      (*predicted)[members[static_cast<size_t>(k)]] = split_label;
      locked[members[static_cast<size_t>(k)]] = true;
    }
    errors += p.split;
  }
  if (p.wrong > 0) {
    if (movable_groups.size() < 2) {
      return Status::Error("perturb labels: too few groups left to move points between");
    }
    size_t smallest = truth.size();
    for (int g : movable_groups) {
      smallest = std::min(smallest, groups[g].size() - (g == order.back() ? p.split : 0));
    }
    if (2 * (p.wrong + p.split) >= static_cast<int>(smallest)) {
      return Status::Error(
          "perturb labels: too many wrong labels for the group sizes (the best matching could "
          "change)");
    }
    std::vector<size_t> candidates;
    for (int g : movable_groups) {
      for (size_t i : groups[g]) {
        if (!locked[i]) {
          candidates.push_back(i);
        }
      }
    }
    std::shuffle(candidates.begin(), candidates.end(), rng);
    for (int k = 0; k < p.wrong; ++k) {
      const size_t i = candidates[static_cast<size_t>(k)];
      std::vector<int> others;
      for (int g : movable_groups) {
        if (g != truth[i]) {
          others.push_back(g);
        }
      }
      (*predicted)[i] = others[std::uniform_int_distribution<size_t>(0, others.size() - 1)(rng)];
    }
    errors += p.wrong;
  }
  if (p.permute) {
    std::vector<int> values;
    for (int v : *predicted) {
      if (std::find(values.begin(), values.end(), v) == values.end()) {
        values.push_back(v);
      }
    }
    std::vector<int> shuffled(values.size());
    std::iota(shuffled.begin(), shuffled.end(), 100);
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    std::map<int, int> relabel;
    for (size_t k = 0; k < values.size(); ++k) {
      relabel[values[k]] = shuffled[k];
    }
    for (int& v : *predicted) {
      v = relabel[v];
    }
  }
  *expected_errors = errors;
  return Status::Ok();
}

}  // namespace eval
}  // namespace mbslam
