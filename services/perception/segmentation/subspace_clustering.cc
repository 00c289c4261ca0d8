#include "services/perception/segmentation/subspace_clustering.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include <Eigen/Eigenvalues>
#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/SVD>

namespace mbslam {

Eigen::MatrixXd SparseSelfExpression(const Eigen::MatrixXd& Y, const SubspaceClusteringOptions& o) {
  const Eigen::Index n = Y.cols();
  const Eigen::MatrixXd G = Y.transpose() * Y;
  // mu_z: the smallest over columns of the largest coherence with another column; the
  // data weight alpha / mu_z makes alpha independent of the data's scale.
  double mu_z = std::numeric_limits<double>::max();
  for (Eigen::Index i = 0; i < n; ++i) {
    double best = 0.0;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (j != i) best = std::max(best, std::abs(G(j, i)));
    }
    mu_z = std::min(mu_z, best);
  }
  if (!(mu_z > 0.0)) mu_z = 1.0;
  const double mu1 = o.alpha / mu_z;
  const double mu2 = o.alpha;
  const Eigen::MatrixXd ones = Eigen::MatrixXd::Ones(n, n);
  const Eigen::MatrixXd A =
      (mu1 * G + mu2 * Eigen::MatrixXd::Identity(n, n) + mu2 * ones).partialPivLu().inverse();
  const Eigen::MatrixXd M0 = A * (mu1 * G + mu2 * ones);
  const Eigen::VectorXd A1 = A * Eigen::VectorXd::Ones(n);

  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd Lambda = Eigen::MatrixXd::Zero(n, n);
  Eigen::RowVectorXd lambda3 = Eigen::RowVectorXd::Zero(n);
  Eigen::MatrixXd Z(n, n);
  const double shrink = 1.0 / mu2;
  for (int iter = 0; iter < o.max_iterations; ++iter) {
    // Z-update (least squares with the affine constraint), zero diagonal.
    Z.noalias() = M0 + A * (mu2 * C - Lambda);
    Z.noalias() -= A1 * lambda3;
    Z.diagonal().setZero();
    // C-update: soft thresholding.
    const Eigen::MatrixXd V = Z + Lambda / mu2;
    C = V.unaryExpr([shrink](double v) {
      return v > shrink ? v - shrink : (v < -shrink ? v + shrink : 0.0);
    });
    C.diagonal().setZero();
    // Dual updates.
    Lambda += mu2 * (Z - C);
    const Eigen::RowVectorXd col_sums = Z.colwise().sum();
    lambda3 += mu2 * (col_sums - Eigen::RowVectorXd::Ones(n));
    const double err1 = (Z - C).cwiseAbs().maxCoeff();
    const double err2 = (col_sums.array() - 1.0).abs().maxCoeff();
    if (err1 < o.tolerance && err2 < o.tolerance) break;
  }
  return C;
}

Eigen::MatrixXd LeastSquaresSelfExpression(const Eigen::MatrixXd& Y, double relative_lambda) {
  const Eigen::Index n = Y.cols();
  Eigen::MatrixXd G = Y.transpose() * Y;
  const double lambda = relative_lambda * G.diagonal().mean();
  G.diagonal().array() += lambda;
  const Eigen::MatrixXd D = G.llt().solve(Eigen::MatrixXd::Identity(n, n));
  Eigen::MatrixXd C(n, n);
  for (Eigen::Index j = 0; j < n; ++j) C.col(j) = -D.col(j) / D(j, j);
  C.diagonal().setZero();
  return C;
}

Eigen::MatrixXd CoefficientAffinity(const Eigen::MatrixXd& C, double mass) {
  const Eigen::Index n = C.cols();
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(n, n);
  std::vector<Eigen::Index> order(static_cast<size_t>(n));
  for (Eigen::Index j = 0; j < n; ++j) {
    const Eigen::VectorXd c = C.col(j).cwiseAbs();
    const double total = c.sum();
    if (total <= 0.0) continue;
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) { return c[a] > c[b]; });
    double kept = 0.0;
    for (Eigen::Index i : order) {
      if (kept >= mass * total) break;
      T(i, j) = C(i, j);
      kept += c[i];
    }
  }
  for (Eigen::Index j = 0; j < n; ++j) {
    const double m = T.col(j).cwiseAbs().maxCoeff();
    if (m > 0.0) T.col(j) /= m;
  }
  return T.cwiseAbs() + T.cwiseAbs().transpose();
}

namespace {

// Eigen-decomposition of the normalised affinity D^-1/2 W D^-1/2 (eigenvalues ascending).
Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> NormalisedAffinity(const Eigen::MatrixXd& W) {
  const Eigen::VectorXd d = W.rowwise().sum();
  Eigen::VectorXd dinv(d.size());
  for (Eigen::Index i = 0; i < d.size(); ++i) dinv[i] = d[i] > 1e-12 ? 1.0 / std::sqrt(d[i]) : 0.0;
  const Eigen::MatrixXd Nmat = dinv.asDiagonal() * W * dinv.asDiagonal();
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Nmat);
}

// k-means++ with restarts; returns labels of the lowest inertia run.
std::vector<int> KMeans(const Eigen::MatrixXd& X, int k, int restarts, int seed) {
  const Eigen::Index n = X.rows();
  std::mt19937 rng(static_cast<uint32_t>(seed));
  std::vector<int> best_labels(static_cast<size_t>(n), 0);
  double best_inertia = std::numeric_limits<double>::max();
  for (int r = 0; r < restarts; ++r) {
    Eigen::MatrixXd centers(k, X.cols());
    std::uniform_int_distribution<Eigen::Index> pick(0, n - 1);
    centers.row(0) = X.row(pick(rng));
    Eigen::VectorXd d2 = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::max());
    for (int c = 1; c < k; ++c) {
      for (Eigen::Index i = 0; i < n; ++i) {
        d2[i] = std::min(d2[i], (X.row(i) - centers.row(c - 1)).squaredNorm());
      }
      std::discrete_distribution<Eigen::Index> dist(d2.data(), d2.data() + n);
      centers.row(c) = X.row(dist(rng));
    }
    std::vector<int> labels(static_cast<size_t>(n), 0);
    double inertia = 0.0;
    for (int iter = 0; iter < 100; ++iter) {
      bool changed = false;
      inertia = 0.0;
      for (Eigen::Index i = 0; i < n; ++i) {
        int best = 0;
        double bd = std::numeric_limits<double>::max();
        for (int c = 0; c < k; ++c) {
          const double dd = (X.row(i) - centers.row(c)).squaredNorm();
          if (dd < bd) {
            bd = dd;
            best = c;
          }
        }
        inertia += bd;
        if (labels[static_cast<size_t>(i)] != best) {
          labels[static_cast<size_t>(i)] = best;
          changed = true;
        }
      }
      Eigen::MatrixXd sums = Eigen::MatrixXd::Zero(k, X.cols());
      std::vector<int> counts(static_cast<size_t>(k), 0);
      for (Eigen::Index i = 0; i < n; ++i) {
        sums.row(labels[static_cast<size_t>(i)]) += X.row(i);
        ++counts[static_cast<size_t>(labels[static_cast<size_t>(i)])];
      }
      for (int c = 0; c < k; ++c) {
        if (counts[static_cast<size_t>(c)] > 0) centers.row(c) = sums.row(c) / counts[static_cast<size_t>(c)];
        else centers.row(c) = X.row(pick(rng));  // revive an empty cluster
      }
      if (!changed && iter > 0) break;
    }
    if (inertia < best_inertia) {
      best_inertia = inertia;
      best_labels = labels;
    }
  }
  return best_labels;
}

}  // namespace

std::vector<int> SpectralClustering(const Eigen::MatrixXd& W, int k, int restarts, int seed) {
  const Eigen::Index n = W.rows();
  if (k <= 1 || n <= k) return std::vector<int>(static_cast<size_t>(n), 0);
  const auto eig = NormalisedAffinity(W);
  Eigen::MatrixXd U = eig.eigenvectors().rightCols(k);  // largest eigenvalues
  for (Eigen::Index i = 0; i < n; ++i) {
    const double norm = U.row(i).norm();
    if (norm > 1e-12) U.row(i) /= norm;
  }
  return KMeans(U, k, restarts, seed);
}

int EstimateGroupCount(const Eigen::MatrixXd& W, int k_max) {
  const Eigen::Index n = W.rows();
  if (n < 3) return 1;
  const auto eig = NormalisedAffinity(W);
  const Eigen::VectorXd ev = eig.eigenvalues().reverse();  // descending
  int best_k = 1;
  double best_gap = -1.0;
  for (int k = 1; k <= std::min<int>(k_max, static_cast<int>(n) - 1); ++k) {
    const double gap = ev[k - 1] - ev[k];
    if (gap > best_gap) {
      best_gap = gap;
      best_k = k;
    }
  }
  return best_k;
}

std::vector<AffineSubspace> FitGroupSubspaces(const Eigen::MatrixXd& Y, const std::vector<int>& labels, int k,
                                              int dimension, int min_members) {
  std::vector<AffineSubspace> out(static_cast<size_t>(std::max(k, 0)));
  for (int g = 0; g < k; ++g) {
    std::vector<Eigen::Index> members;
    for (Eigen::Index i = 0; i < Y.cols(); ++i) {
      if (labels[static_cast<size_t>(i)] == g) members.push_back(i);
    }
    AffineSubspace& s = out[static_cast<size_t>(g)];
    s.members = static_cast<int>(members.size());
    if (members.empty() || s.members < min_members) continue;
    Eigen::MatrixXd M(Y.rows(), static_cast<Eigen::Index>(members.size()));
    for (size_t m = 0; m < members.size(); ++m) M.col(static_cast<Eigen::Index>(m)) = Y.col(members[m]);
    s.mean = M.rowwise().mean();
    M.colwise() -= s.mean;
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeThinU);
    s.basis = svd.matrixU().leftCols(std::min<Eigen::Index>(dimension, svd.matrixU().cols()));
  }
  return out;
}

std::vector<int> RefineBySubspaces(const Eigen::MatrixXd& Y, std::vector<int> labels, int k,
                                   int dimension, int iterations) {
  const Eigen::Index n = Y.cols();
  for (int iter = 0; iter < iterations; ++iter) {
    const std::vector<AffineSubspace> subspaces = FitGroupSubspaces(Y, labels, k, dimension, dimension + 2);
    bool changed = false;
    for (Eigen::Index i = 0; i < n; ++i) {
      int best = labels[static_cast<size_t>(i)];
      double best_r = std::numeric_limits<double>::max();
      for (int c = 0; c < k; ++c) {
        if (!subspaces[static_cast<size_t>(c)].valid()) continue;
        const double r = subspaces[static_cast<size_t>(c)].SquaredDistance(Y.col(i));
        if (r < best_r) {
          best_r = r;
          best = c;
        }
      }
      if (best != labels[static_cast<size_t>(i)]) {
        labels[static_cast<size_t>(i)] = best;
        changed = true;
      }
    }
    if (!changed) break;
  }
  return labels;
}

double SubspaceResidual(const Eigen::MatrixXd& Y, const std::vector<int>& labels, int group,
                        int dimension) {
  std::vector<Eigen::Index> members;
  for (Eigen::Index i = 0; i < Y.cols(); ++i) {
    if (labels[static_cast<size_t>(i)] == group) members.push_back(i);
  }
  if (static_cast<int>(members.size()) <= dimension + 1) return 0.0;
  Eigen::MatrixXd M(Y.rows(), static_cast<Eigen::Index>(members.size()));
  for (size_t m = 0; m < members.size(); ++m) M.col(static_cast<Eigen::Index>(m)) = Y.col(members[m]);
  M.colwise() -= M.rowwise().mean();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(M);
  double r = 0.0;
  for (Eigen::Index j = dimension; j < svd.singularValues().size(); ++j) {
    r += svd.singularValues()[j] * svd.singularValues()[j];
  }
  return r / static_cast<double>(members.size());
}

std::vector<int> MergeGroups(const Eigen::MatrixXd& Y, std::vector<int> labels, int dimension,
                             double merge_ratio, int* groups) {
  int k = 0;
  for (int l : labels) k = std::max(k, l + 1);
  while (k > 1) {
    double best_ratio = std::numeric_limits<double>::max();
    int best_a = -1, best_b = -1;
    for (int a = 0; a < k; ++a) {
      for (int b = a + 1; b < k; ++b) {
        std::vector<int> merged = labels;
        for (int& l : merged) {
          if (l == b) l = a;
        }
        const double separate = std::max(SubspaceResidual(Y, labels, a, dimension),
                                         SubspaceResidual(Y, labels, b, dimension));
        const double joint = SubspaceResidual(Y, merged, a, dimension);
        const double ratio = joint / std::max(separate, 1e-12);
        if (ratio < best_ratio) {
          best_ratio = ratio;
          best_a = a;
          best_b = b;
        }
      }
    }
    if (best_ratio > merge_ratio) break;
    for (int& l : labels) {
      if (l == best_b) l = best_a;
      else if (l == k - 1 && best_b != k - 1) l = best_b;  // keep labels 0..k-2
    }
    --k;
  }
  *groups = k;
  return labels;
}

double TotalSubspaceResidual(const Eigen::MatrixXd& Y, const std::vector<int>& labels, int dimension) {
  int k = 0;
  for (int l : labels) k = std::max(k, l + 1);
  double total = 0.0;
  for (int g = 0; g < k; ++g) {
    const auto n = std::count(labels.begin(), labels.end(), g);
    total += SubspaceResidual(Y, labels, g, dimension) * static_cast<double>(n);
  }
  return total;
}

namespace {

// Spectral clustering of W into k groups, then the K-subspaces refinement unless it
// moves more than max_refine_moved of the points: then the subspaces are not separable
// by residual (dependent motions) and the spectral answer is kept.
std::vector<int> SpectralAndRefine(const Eigen::MatrixXd& Y, const Eigen::MatrixXd& W, int k,
                                   const SubspaceClusteringOptions& o) {
  std::vector<int> labels = SpectralClustering(W, k, o.kmeans_restarts, o.seed);
  if (o.refine_iterations <= 0 || k <= 1) return labels;
  std::vector<int> refined = RefineBySubspaces(Y, labels, k, o.subspace_dimension, o.refine_iterations);
  size_t moved = 0;
  for (size_t i = 0; i < labels.size(); ++i) moved += refined[i] != labels[i];
  if (static_cast<double>(moved) <= o.max_refine_moved * static_cast<double>(labels.size())) {
    return refined;
  }
  return labels;
}

}  // namespace

std::vector<int> SegmentByHypotheses(const Eigen::MatrixXd& Y, const Eigen::MatrixXd& C, int k,
                                     const SubspaceClusteringOptions& o, double* residual) {
  std::vector<int> best;
  double best_residual = std::numeric_limits<double>::max();
  for (double mass : o.coefficient_masses) {
    std::vector<int> labels = SpectralAndRefine(Y, CoefficientAffinity(C, mass), k, o);
    const double r = TotalSubspaceResidual(Y, labels, o.selection_dimension);
    if (r < best_residual) {  // ties keep the earlier (smaller) mass
      best_residual = r;
      best = std::move(labels);
    }
  }
  if (residual) *residual = best_residual;
  return best;
}

double NormalizedCut(const Eigen::MatrixXd& W, const std::vector<int>& labels) {
  int k = 0;
  for (int l : labels) k = std::max(k, l + 1);
  if (k <= 1) return 0.0;
  std::vector<double> cut(static_cast<size_t>(k), 0.0), volume(static_cast<size_t>(k), 0.0);
  for (Eigen::Index j = 0; j < W.cols(); ++j) {
    const int gj = labels[static_cast<size_t>(j)];
    for (Eigen::Index i = 0; i < W.rows(); ++i) {
      volume[static_cast<size_t>(gj)] += W(i, j);
      if (labels[static_cast<size_t>(i)] != gj) cut[static_cast<size_t>(gj)] += W(i, j);
    }
  }
  double total = 0.0;
  for (int g = 0; g < k; ++g) {
    total += volume[static_cast<size_t>(g)] > 0.0 ? cut[static_cast<size_t>(g)] / volume[static_cast<size_t>(g)] : 1.0;
  }
  return total;
}

double SubspaceSilhouette(const Eigen::MatrixXd& Y, const std::vector<int>& labels, int dimension) {
  int k = 0;
  for (int l : labels) k = std::max(k, l + 1);
  if (k <= 1) return 0.0;
  const std::vector<AffineSubspace> subspaces = FitGroupSubspaces(Y, labels, k, dimension, dimension + 2);
  double total = 0.0;
  int counted = 0;
  for (Eigen::Index i = 0; i < Y.cols(); ++i) {
    const int own = labels[static_cast<size_t>(i)];
    if (!subspaces[static_cast<size_t>(own)].valid()) continue;
    auto distance = [&](int g) { return std::sqrt(subspaces[static_cast<size_t>(g)].SquaredDistance(Y.col(i))); };
    const double a = distance(own);
    double b = std::numeric_limits<double>::max();
    for (int g = 0; g < k; ++g) {
      if (g != own && subspaces[static_cast<size_t>(g)].valid()) b = std::min(b, distance(g));
    }
    if (b == std::numeric_limits<double>::max()) continue;
    total += (b - a) / std::max({a, b, 1e-12});
    ++counted;
  }
  return counted > 0 ? total / counted : 0.0;
}

std::vector<int> SelectGroupCount(const Eigen::MatrixXd& Y, const Eigen::MatrixXd& C,
                                  const SubspaceClusteringOptions& o, int* groups) {
  const Eigen::MatrixXd W = CoefficientAffinity(C, o.order_cut_mass);
  std::vector<int> best(static_cast<size_t>(Y.cols()), 0);
  const double residual_1 = std::max(TotalSubspaceResidual(Y, best, o.selection_dimension), 1e-12);
  const bool silhouette = o.order_selection == "silhouette";
  double best_score = silhouette ? -std::numeric_limits<double>::max() : 0.0;  // cut, k = 1: log(1) + 0
  double best_silhouette = 0.0;
  *groups = 1;
  const int k_max = std::min<int>(o.max_motions, static_cast<int>(Y.cols()) / (o.subspace_dimension + 2));
  for (int k = 2; k <= k_max; ++k) {
    double residual = 0.0;
    std::vector<int> labels = SegmentByHypotheses(Y, C, k, o, &residual);
    const double log_ratio = std::log(std::max(residual, 1e-12) / residual_1);
    if (silhouette) {
      const double sil = SubspaceSilhouette(Y, labels, o.selection_dimension);
      const double score = sil - o.silhouette_cut_weight * NormalizedCut(W, labels) - o.silhouette_residual_weight * log_ratio;
      if (score > best_score) {
        best_score = score;
        best_silhouette = sil;
        best = std::move(labels);
        *groups = k;
      }
      continue;
    }
    const double score = log_ratio + o.order_cut_weight * NormalizedCut(W, labels);
    if (score < best_score) {
      best_score = score;
      best = std::move(labels);
      *groups = k;
    }
  }
  if (silhouette && *groups > 1 && best_silhouette < o.min_silhouette) {
    best.assign(static_cast<size_t>(Y.cols()), 0);
    *groups = 1;
  }
  return best;
}

std::vector<int> ClusterTrajectories(const Eigen::MatrixXd& Y, int k,
                                     const SubspaceClusteringOptions& o, int* k_used) {
  Eigen::MatrixXd data = Y;
  if (k > 0 && o.projection_dims_per_motion > 0) {
    const Eigen::Index r = std::min<Eigen::Index>(static_cast<Eigen::Index>(k) * o.projection_dims_per_motion, Y.rows());
    if (r < Y.rows()) {
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(Y, Eigen::ComputeThinU);
      data = svd.matrixU().leftCols(r).transpose() * Y;
    }
  }
  const Eigen::MatrixXd C = o.method == "lsr" ? LeastSquaresSelfExpression(data, o.lsr_lambda)
                                              : SparseSelfExpression(data, o);
  if (k > 0) {
    if (k_used) *k_used = k;
    return SegmentByHypotheses(Y, C, k, o);
  }
  if (o.order_selection == "cut" || o.order_selection == "silhouette") {
    int groups = 1;
    std::vector<int> labels = SelectGroupCount(Y, C, o, &groups);
    if (k_used) *k_used = groups;
    return labels;
  }
  const Eigen::MatrixXd W = CoefficientAffinity(C, o.order_cut_mass);
  int groups = o.order_selection == "eigengap" ? EstimateGroupCount(W, o.max_motions) : o.max_motions;
  std::vector<int> labels = SpectralClustering(W, groups, o.kmeans_restarts, o.seed);
  if (o.order_selection == "merge") {
    labels = RefineBySubspaces(Y, std::move(labels), groups, o.subspace_dimension, o.refine_iterations);
    labels = MergeGroups(Y, std::move(labels), o.subspace_dimension, o.merge_ratio, &groups);
  }
  if (k_used) *k_used = groups;
  if (o.refine_iterations > 0 && groups > 1) {
    std::vector<int> refined =
        RefineBySubspaces(Y, labels, groups, o.subspace_dimension, o.refine_iterations);
    size_t moved = 0;
    for (size_t i = 0; i < labels.size(); ++i) moved += refined[i] != labels[i];
    if (static_cast<double>(moved) <= o.max_refine_moved * static_cast<double>(labels.size())) {
      labels = std::move(refined);
    }
  }
  return labels;
}

}  // namespace mbslam
