#ifndef MBSLAM_TOOLS_EVAL_ALIGNMENT_H_
#define MBSLAM_TOOLS_EVAL_ALIGNMENT_H_

// Least-squares alignment of point sets (Umeyama 1991): the similarity (or rigid
// transform) S minimising sum_i |dst_i - S * src_i|^2.

#include <Eigen/Core>

#include <vector>

#include "common/util/status.h"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {
namespace eval {

// with_scale = false gives the best rigid transform (scale 1). Needs >= 3 points that
// are not all on one line (>= 1 point for a translation-only problem is not supported).
Status UmeyamaAlignment(const std::vector<Eigen::Vector3d>& src,
                        const std::vector<Eigen::Vector3d>& dst, bool with_scale,
                        Sim3d* dst_from_src);

// For a path along one line (a car driving straight), where the positions leave the
// rotation about the line undetermined: the rotation from the camera orientations (the
// chordal mean of R_dst_i R_src_i^T, projected onto SO(3)), then the scale and
// translation by least squares on the positions. Needs >= 2 poses whose positions do
// not all coincide when with_scale.
Status OrientationAlignment(const std::vector<Rigid3d>& src, const std::vector<Rigid3d>& dst,
                            bool with_scale, Sim3d* dst_from_src);

}  // namespace eval
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_EVAL_ALIGNMENT_H_
