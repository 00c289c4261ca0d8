#ifndef MBSLAM_SERVICES_PERCEPTION_GEOMETRY_POLYGON_H_
#define MBSLAM_SERVICES_PERCEPTION_GEOMETRY_POLYGON_H_

// Image-plane convex hulls (object outlines, occlusion tests).

#include <vector>

#include <Eigen/Core>

namespace mbslam {

// Convex hull, counter-clockwise in a y-down image (Andrew's monotone chain).
std::vector<Eigen::Vector2f> ConvexHull(std::vector<Eigen::Vector2f> points);

// True if p lies inside (or on) a convex polygon of either orientation.
bool InsideConvexHull(const std::vector<Eigen::Vector2f>& hull, const Eigen::Vector2f& p);

// Area of a simple polygon (absolute value).
double PolygonArea(const std::vector<Eigen::Vector2f>& polygon);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_GEOMETRY_POLYGON_H_
