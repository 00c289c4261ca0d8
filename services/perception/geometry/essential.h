#ifndef MBSLAM_SERVICES_PERCEPTION_GEOMETRY_ESSENTIAL_H_
#define MBSLAM_SERVICES_PERCEPTION_GEOMETRY_ESSENTIAL_H_

// The essential matrix of two calibrated views from five correspondences, and its robust
// estimation (RANSAC) from many. Convention: x_n^T E x_r = 0 for normalised image points
// x_r (reference view) and x_n (current view), E = [t]x R with x_n ~ R x_r + t.
//
// The minimal solver is Stewenius' Groebner-basis form of the five-point problem: E lies
// in the 4-dimensional null space of the five epipolar constraints, E = x X + y Y + z Z + W;
// det(E) = 0 and 2 E E^T E - tr(E E^T) E = 0 are ten cubics in (x, y, z); eliminating their
// ten cubic monomials leaves the action of x on the ten monomials of degree <= 2, whose real
// eigenvectors are the solutions. It replaces OpenCV's findEssentialMat, whose solver finds
// the roots of the tenth-degree polynomial with 300 fixed Durand-Kerner sweeps (about 1.3 M
// instructions per sample on this machine, most of the segmentation's time).

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/util/status.h"

namespace mbslam {

// Up to ten essential matrices through the five correspondences (normalised coordinates),
// each of unit Frobenius norm. Empty when the points are degenerate.
std::vector<Eigen::Matrix3d> FivePointEssentials(const Eigen::Vector2d x_r[5], const Eigen::Vector2d x_n[5]);

// The squared Sampson distance of a correspondence to E (normalised units squared): the
// error OpenCV's findEssentialMat thresholds, so thresholds keep their meaning.
double SampsonDistanceSquared(const Eigen::Matrix3d& E, const Eigen::Vector2d& x_r, const Eigen::Vector2d& x_n);

struct EssentialRansacOptions {
  double threshold = 1e-3;     // inlier threshold on the Sampson distance (normalised units)
  double confidence = 0.999;   // stop when a better model is this unlikely to exist
  int max_iterations = 1000;   // samples at most
  uint32_t seed = 0x5eed;      // the sampler's seed: every call with the same input gives the same result
  int min_iterations = 0;      // samples at least, whatever the adaptive rule says
  // MSAC: a model's cost is the sum of its squared Sampson distances, each capped at the
  // threshold's square (the lowest wins), rather than its inlier count: among models
  // with about as many inliers, the one that fits them best.
  bool msac = false;

  bool Check() const {
    return threshold > 0.0 && confidence > 0.0 && confidence < 1.0 && max_iterations >= 1 && min_iterations >= 0;
  }
};

struct EssentialRansacResult {
  Eigen::Matrix3d E = Eigen::Matrix3d::Zero();
  std::vector<uint8_t> inliers;  // per correspondence, within the threshold of E
  int num_inliers = 0;
  int iterations = 0;            // samples drawn
};

// RANSAC over five-point samples with the adaptive stopping rule (the number of samples
// shrinks as the best inlier share grows, as in OpenCV's RANSAC). Fails with fewer than
// five correspondences or when no sample gives a model.
Status EstimateEssentialRansac(const std::vector<Eigen::Vector2d>& x_r, const std::vector<Eigen::Vector2d>& x_n,
                               const EssentialRansacOptions& options, EssentialRansacResult* result);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_GEOMETRY_ESSENTIAL_H_
