#ifndef MBSLAM_SERVICES_PERCEPTION_SLAM_INIT_SELECTION_H_
#define MBSLAM_SERVICES_PERCEPTION_SLAM_INIT_SELECTION_H_

// Which motion of the initialisation's two views is the static world (thesis sec. 3.4,
// 4.4: the static world is the dominant consistent motion). A plain essential-matrix
// RANSAC picks the motion with most inliers, which is a large compact moving object as
// soon as it holds more tracks than the background (a car the camera follows, DAVIS
// car-shadow). Here the correspondences are split into motion groups by sequential
// RANSAC (largest group, its inliers removed, again), and the static world is the group
// that covers the image most broadly (share of the grid cells holding features where the
// group is the majority), not the one with most inliers; a group inside moving-object
// hulls is never chosen.

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace mbslam {

struct InitMotionGroup {
  std::vector<uint8_t> inliers;  // per correspondence (1 = member)
  int count = 0;                 // members
  double coverage = 0.0;         // share of the feature cells where the group is the majority
  double hull_share = 0.0;       // share of members inside a moving object's hull
};

// Sequential essential-matrix RANSAC on two views (normalised coordinates, reference
// xr and current xn): at most max_groups groups of at least min_count members each,
// largest first; threshold in normalised units (the Sampson distance of OpenCV).
std::vector<InitMotionGroup> FindMotionGroups(const std::vector<Eigen::Vector2d>& xr,
                                              const std::vector<Eigen::Vector2d>& xn, double threshold,
                                              int min_count, int max_groups);

// Fills coverage and hull_share of each group. The grid (cols x rows cells) spans the
// bounding box of all features of the current image (all_xy, normalised); coverage is
// the number of cells where the group holds at least half of the correspondences (and
// at least two), divided by the number of cells holding any feature of the image.
// With require_majority false a cell counts as soon as it holds two members (for a
// subset such as the triangulated points, which need not be the majority anywhere).
void ScoreMotionGroups(const std::vector<Eigen::Vector2d>& xn, const std::vector<Eigen::Vector2d>& all_xy,
                       const std::vector<std::vector<Eigen::Vector2f>>& moving_hulls_xy, int cols, int rows,
                       std::vector<InitMotionGroup>* groups, bool require_majority = true);

// The static world's group: the broadest coverage (ties: more members) among the groups
// with coverage >= min_coverage and hull_share <= max_hull_share; -1 if none qualifies.
int SelectStaticGroup(const std::vector<InitMotionGroup>& groups, double min_coverage, double max_hull_share);

// Two views whose relative rotation is known (cam1_from_cam0 = R, e.g. an object's SLAM
// given the camera's own rotation): the translation direction t is then the only unknown,
// with x1 . (t x R x0) = 0, i.e. t orthogonal to n = (R x0) x x1 for every
// correspondence. Two-point RANSAC (t = n_i x n_j), inliers by the Sampson distance of
// E = [t]x R under `threshold` (normalised units), refined by least squares on the
// inliers. The sign of t is left open (cheirality decides). Deterministic (fixed seed).
// nullopt when fewer than 2 inliers or degenerate.
struct KnownRotationTranslation {
  Eigen::Vector3d t_unit = Eigen::Vector3d::Zero();
  std::vector<uint8_t> inliers;
  int count = 0;
};
std::optional<KnownRotationTranslation> TranslationGivenRotation(const std::vector<Eigen::Vector2d>& x0,
                                                                 const std::vector<Eigen::Vector2d>& x1,
                                                                 const Eigen::Matrix3d& cam1_from_cam0,
                                                                 double threshold, int iterations);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_SLAM_INIT_SELECTION_H_
