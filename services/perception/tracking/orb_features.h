#ifndef MBSLAM_SERVICES_PERCEPTION_TRACKING_ORB_FEATURES_H_
#define MBSLAM_SERVICES_PERCEPTION_TRACKING_ORB_FEATURES_H_

// ORB descriptors (rBRIEF, 256 bits; OpenCV's) for matching where tracks do not carry a
// feature over: the tracker's wide-baseline fallback and SLAM's relocalisation. Both
// sides are described alike: on the full-resolution image only (one pyramid level) and
// oriented by ORB's intensity centroid, whether the points are given (a map point's
// track in a keyframe) or detected (FAST corners of a new image).

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

namespace mbslam {

struct OrbDescriptor {
  std::array<uint8_t, 32> bits{};
};

// Hamming distance of two binary descriptors of `bytes` bytes (as cv::NORM_HAMMING,
// without a Mat header per pair).
int HammingDistance(const uint8_t* a, const uint8_t* b, int bytes);
inline int HammingDistance(const OrbDescriptor& a, const OrbDescriptor& b) {
  return HammingDistance(a.bits.data(), b.bits.data(), static_cast<int>(a.bits.size()));
}

// ORB's orientation of a point (the intensity centroid of the disc of radius 15 around
// it, degrees in [0, 360)), for descriptors computed at given positions: cv::ORB::compute
// takes a provided keypoint's angle as it is, and the keypoints it detects are oriented.
// -1 when the disc leaves the image.
float IntensityCentroidAngle(const cv::Mat& image, const cv::Point2f& pt);

// Describes the 8-bit gray `image` at `points` (px), oriented: (*valid)[i] is 0 where
// the point is too near the border for ORB's 31 px patch (its descriptor is then zero).
void DescribeOrbAt(const cv::Mat& image, const std::vector<Eigen::Vector2f>& points,
                   std::vector<OrbDescriptor>* descriptors, std::vector<uint8_t>* valid);

// Up to max_features FAST corners of `image` (threshold in grey levels, ranked by the
// Harris score, at least 31 px from the border), oriented and described.
void DetectOrb(const cv::Mat& image, int max_features, int fast_threshold,
               std::vector<Eigen::Vector2f>* points, std::vector<OrbDescriptor>* descriptors);

// One-to-one matches (query index, train index): each query's nearest train descriptor
// when it is within max_hamming bits, nearer than ratio x the second nearest (Lowe's
// test) and strictly nearer than it; a train descriptor claimed twice goes to the nearer
// query.
std::vector<std::pair<int, int>> MatchOrb(const std::vector<OrbDescriptor>& query,
                                          const std::vector<OrbDescriptor>& train, int max_hamming,
                                          double ratio);

// One-to-one matches (query index, train index) of queries with a predicted position:
// the same test as MatchOrb, but each query is compared only with the train points
// within radius_px of query_uv (a track's last position, a map point's projection).
// Queries and train points whose position is not finite are skipped; radius_px must be
// positive and finite (else no match). The shorter of each position / descriptor pair of
// vectors counts. In query order.
std::vector<std::pair<int, int>> MatchOrbWithinRadius(const std::vector<Eigen::Vector2f>& query_uv,
                                                      const std::vector<OrbDescriptor>& query,
                                                      const std::vector<Eigen::Vector2f>& train_uv,
                                                      const std::vector<OrbDescriptor>& train,
                                                      double radius_px, int max_hamming,
                                                      double ratio);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_TRACKING_ORB_FEATURES_H_
