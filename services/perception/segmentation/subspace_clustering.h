#ifndef MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_SUBSPACE_CLUSTERING_H_
#define MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_SUBSPACE_CLUSTERING_H_

// Multi-view multibody segmentation of feature trajectories: the initialisation step of
// thesis sec. 3.4 (the thesis uses the algebraic RAS; this is a multi-view algebraic
// method in the same family). Under an affine camera the trajectories of one rigid
// motion, stacked as 2F-vectors, lie in an affine subspace of dimension <= 3, so the
// motions are found by subspace clustering: sparse self-expression (SSC, Elhamifar &
// Vidal) solved by ADMM, an affinity from the sparse coefficients, and normalised
// spectral clustering. The number of motions is given, or estimated (by default from the
// subspace silhouette of the segmentations into 2..max_motions groups, see
// SelectGroupCount).

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/config/options.h"

namespace mbslam {

struct SubspaceClusteringOptions {
  std::string method = "ssc";       // "ssc" (sparse, ADMM; offline quality) or "lsr" (least squares, closed form; fast)
  double lsr_lambda = 0.005;        // LSR regularisation relative to the mean squared column norm
  double alpha = 800.0;             // data term weight relative to the smallest coherence (SSC's alpha)
  int max_iterations = 300;         // ADMM iterations (count)
  double tolerance = 2e-4;          // ADMM stopping tolerance on the constraints
  // Affinity hypotheses: each column keeps its largest coefficients up to each of these
  // shares of its L1 mass; every share gives one segmentation (spectral + refinement) and
  // the one that the affine camera model explains best is kept.
  std::vector<double> coefficient_masses = {0.5, 0.6, 0.7, 0.8, 0.9, 1.0};
  int selection_dimension = 3;      // hypotheses compared by their residual to affine subspaces of this dimension (3 = affine camera)
  int projection_dims_per_motion = 4;  // project the data to this many dims per motion when k is known; 0 = none
  int kmeans_restarts = 20;         // k-means restarts in the spectral embedding (count)
  int max_motions = 5;              // largest number of motions considered when estimating it (count)
  int seed = 1;                     // k-means seed (deterministic)
  int refine_iterations = 20;       // K-subspaces refinement after spectral clustering; 0 = off (count)
  int subspace_dimension = 4;       // dimension of one motion's trajectory subspace in the refinement (3 affine + 1 for perspective)
  double max_refine_moved = 0.25;   // a refinement that moves more than this share of the points is rejected
  std::string order_selection = "silhouette";  // unknown k: "silhouette" (subspace separation, see SelectGroupCount), "cut" (residual vs graph cut), "merge" (over-segment, merge by residual) or "eigengap"
  double order_cut_weight = 4.0;    // "cut": weight of the normalised cut against the log residual
  double order_cut_mass = 0.7;      // "cut": coefficient mass of the affinity whose cut is measured
  double merge_ratio = 2.0;         // merge two groups while one subspace fits them within this factor of two
  double silhouette_cut_weight = 0.2;       // "silhouette": weight of the normalised cut subtracted from the silhouette
  double silhouette_residual_weight = 0.05;  // "silhouette": weight of the log residual ratio (fit) subtracted from it
  double min_silhouette = 0.4;      // "silhouette": below this subspace silhouette the best split is no split (one motion)

  bool Check() const {
    MBSLAM_CHECK_OPTION(method == "ssc" || method == "lsr");
    MBSLAM_CHECK_OPTION_GT(lsr_lambda, 0.0);
    MBSLAM_CHECK_OPTION_GT(alpha, 0.0);
    MBSLAM_CHECK_OPTION_GT(max_iterations, 0);
    MBSLAM_CHECK_OPTION_GT(tolerance, 0.0);
    MBSLAM_CHECK_OPTION(!coefficient_masses.empty());
    for (double m : coefficient_masses) MBSLAM_CHECK_OPTION(m > 0.0 && m <= 1.0);
    MBSLAM_CHECK_OPTION_GE(selection_dimension, 1);
    MBSLAM_CHECK_OPTION_GE(projection_dims_per_motion, 0);
    MBSLAM_CHECK_OPTION_GT(kmeans_restarts, 0);
    MBSLAM_CHECK_OPTION_GE(max_motions, 1);
    MBSLAM_CHECK_OPTION_GE(refine_iterations, 0);
    MBSLAM_CHECK_OPTION_GE(subspace_dimension, 1);
    MBSLAM_CHECK_OPTION(max_refine_moved >= 0.0 && max_refine_moved <= 1.0);
    MBSLAM_CHECK_OPTION(order_selection == "silhouette" || order_selection == "cut" || order_selection == "merge" ||
                        order_selection == "eigengap");
    MBSLAM_CHECK_OPTION_GE(silhouette_cut_weight, 0.0);
    MBSLAM_CHECK_OPTION_GE(silhouette_residual_weight, 0.0);
    MBSLAM_CHECK_OPTION(min_silhouette >= -1.0 && min_silhouette <= 1.0);
    MBSLAM_CHECK_OPTION_GT(order_cut_weight, 0.0);
    MBSLAM_CHECK_OPTION(order_cut_mass > 0.0 && order_cut_mass <= 1.0);
    MBSLAM_CHECK_OPTION_GT(merge_ratio, 1.0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("method", &method, "ssc (sparse, ADMM) | lsr (least squares, closed form, fast)");
    v("lsr_lambda", &lsr_lambda, "LSR regularisation relative to the mean squared column norm");
    v("alpha", &alpha, "SSC data weight relative to the smallest coherence");
    v("max_iterations", &max_iterations, "ADMM iterations (count)");
    v("tolerance", &tolerance, "ADMM stopping tolerance");
    v("coefficient_masses", &coefficient_masses, "shares of each column's L1 mass kept, one affinity hypothesis each");
    v("selection_dimension", &selection_dimension, "hypotheses compared by residual to affine subspaces of this dimension");
    v("projection_dims_per_motion", &projection_dims_per_motion, "projection dims per motion when k is known (0 = none)");
    v("kmeans_restarts", &kmeans_restarts, "k-means restarts (count)");
    v("max_motions", &max_motions, "largest number of motions considered (count)");
    v("seed", &seed, "k-means seed");
    v("refine_iterations", &refine_iterations, "K-subspaces refinement iterations (0 = off)");
    v("subspace_dimension", &subspace_dimension, "subspace dimension per motion in the refinement");
    v("max_refine_moved", &max_refine_moved, "refinements moving more than this share are rejected");
    v("order_selection", &order_selection, "unknown number of motions: silhouette | cut | merge | eigengap");
    v("order_cut_weight", &order_cut_weight, "cut: weight of the normalised cut against the log residual");
    v("order_cut_mass", &order_cut_mass, "cut: coefficient mass of the affinity whose cut is measured");
    v("merge_ratio", &merge_ratio, "merge groups while one subspace fits them within this factor");
    v("silhouette_cut_weight", &silhouette_cut_weight, "silhouette: weight of the normalised cut against the silhouette");
    v("silhouette_residual_weight", &silhouette_residual_weight, "silhouette: weight of the log residual ratio against the silhouette");
    v("min_silhouette", &min_silhouette, "silhouette: smallest silhouette of a split into several motions");
  }
};

// Sparse self-expressive coefficients C (N x N, zero diagonal, columns summing to one)
// of the columns of Y (D x N).
Eigen::MatrixXd SparseSelfExpression(const Eigen::MatrixXd& Y, const SubspaceClusteringOptions& options);

// Least-squares self-expression with a zero diagonal (LSR, Lu et al. 2012), closed form:
// C = -D diag(D)^-1 with D = (Y^T Y + lambda I)^-1, diag(C) = 0.
Eigen::MatrixXd LeastSquaresSelfExpression(const Eigen::MatrixXd& Y, double relative_lambda);

// Symmetric affinity from the coefficients: each column thresholded to its largest
// entries holding `mass` of its L1 norm and scaled by its maximum; W = |C| + |C|^T.
Eigen::MatrixXd CoefficientAffinity(const Eigen::MatrixXd& C, double mass);

// Normalised spectral clustering (Ng, Jordan, Weiss) into k groups; labels 0..k-1.
std::vector<int> SpectralClustering(const Eigen::MatrixXd& W, int k, int restarts, int seed);

// Number of groups in [1, k_max] with the largest eigengap of the normalised Laplacian.
int EstimateGroupCount(const Eigen::MatrixXd& W, int k_max);

// An affine subspace fitted to a group of trajectories: its mean and an orthonormal
// basis (empty when the group had too few members to fit).
struct AffineSubspace {
  Eigen::VectorXd mean;
  Eigen::MatrixXd basis;
  int members = 0;  // columns of the group
  bool valid() const { return basis.size() > 0; }
  // Squared distance of y to the subspace.
  double SquaredDistance(const Eigen::VectorXd& y) const {
    const Eigen::VectorXd d = y - mean;
    return (d - basis * (basis.transpose() * d)).squaredNorm();
  }
};

// For each group g in [0, k): the affine subspace of the given dimension through the
// columns of Y labelled g (mean, then the leading left singular vectors of the centred
// columns); groups with fewer than min_members columns are left without one.
std::vector<AffineSubspace> FitGroupSubspaces(const Eigen::MatrixXd& Y, const std::vector<int>& labels, int k,
                                              int dimension, int min_members);

// K-subspaces refinement: each point moves to the affine subspace (of the given
// dimension, fitted to the current groups) that explains it best, until stable.
std::vector<int> RefineBySubspaces(const Eigen::MatrixXd& Y, std::vector<int> labels, int k,
                                   int dimension, int iterations);

// Mean squared residual per point of the trajectories of each group to its best
// affine subspace of the given dimension.
double SubspaceResidual(const Eigen::MatrixXd& Y, const std::vector<int>& labels, int group, int dimension);

// Model order by merging: starting from an over-segmentation into k_max groups, the
// pair of groups whose union is best explained by one subspace is merged while the
// union's residual stays within `merge_ratio` of the separate fits.
std::vector<int> MergeGroups(const Eigen::MatrixXd& Y, std::vector<int> labels, int dimension,
                             double merge_ratio, int* groups);

// Sum over groups of the squared residuals of the trajectories to their group's best
// affine subspace of the given dimension (groups of at most dimension + 1 points: 0).
double TotalSubspaceResidual(const Eigen::MatrixXd& Y, const std::vector<int>& labels, int dimension);

// Segmentation into k groups from self-expressive coefficients C of the columns of Y:
// for every coefficient mass of the options one hypothesis (affinity, spectral
// clustering, K-subspaces refinement kept unless it moves more than max_refine_moved of
// the points); the hypothesis with the smallest TotalSubspaceResidual at
// selection_dimension is returned (its residual in *residual).
std::vector<int> SegmentByHypotheses(const Eigen::MatrixXd& Y, const Eigen::MatrixXd& C, int k,
                                     const SubspaceClusteringOptions& options, double* residual = nullptr);

// Sum over groups of cut(group, rest) / volume(group) in the affinity W (0 for one group).
double NormalizedCut(const Eigen::MatrixXd& W, const std::vector<int>& labels);

// Mean over points of the subspace silhouette (b - a) / max(a, b): a the distance of a
// point to the affine subspace (of the given dimension) fitted to its own group, b the
// smallest distance to another group's. Near 1 for well separated subspaces, near 0
// when one motion is split in two (both halves fit the same subspace). Groups of fewer
// than dimension + 2 points are skipped; 0 for one group.
double SubspaceSilhouette(const Eigen::MatrixXd& Y, const std::vector<int>& labels, int dimension);

// Model order (order_selection "cut") by a penalised criterion: for every k in [1, max_motions] the
// SegmentByHypotheses segmentation; k minimises
//   log(residual_k / residual_1) + order_cut_weight * NormalizedCut(W, labels_k),
// the affine model's fit (which always improves with more groups) against the
// self-expressive evidence the groups cut (which grows when a motion is split).
// order_selection "silhouette": k in [2, max_motions] maximises
//   SubspaceSilhouette(labels_k) - silhouette_cut_weight * NormalizedCut(W, labels_k)
//     - silhouette_residual_weight * log(residual_k / residual_1),
// and k = 1 when the silhouette of that k is below min_silhouette.
// Returns the labels, the number of groups in *groups.
std::vector<int> SelectGroupCount(const Eigen::MatrixXd& Y, const Eigen::MatrixXd& C,
                                  const SubspaceClusteringOptions& options, int* groups);

// The whole method on trajectories Y (2F x N). k <= 0: estimate the number of motions.
std::vector<int> ClusterTrajectories(const Eigen::MatrixXd& Y, int k,
                                     const SubspaceClusteringOptions& options, int* k_used = nullptr);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_SUBSPACE_CLUSTERING_H_
