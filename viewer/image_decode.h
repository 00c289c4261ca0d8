#ifndef MBSLAM_VIEWER_IMAGE_DECODE_H_
#define MBSLAM_VIEWER_IMAGE_DECODE_H_

#include <opencv2/core.hpp>

#include "common/util/status.h"
#include "viewer/scene.h"

namespace mbslam {
namespace viewer {

// Turns an image_t payload (raw gray / RGB / BGR rows with their stride, or JPEG / PNG
// file bytes) into a BGR image. The geometry is checked against the byte count and
// max_dimension before anything is allocated; a compressed image must decode to the
// announced size (when one is announced).
Status DecodeToBgr(const EncodedImage& image, int max_dimension, cv::Mat* bgr);

}  // namespace viewer
}  // namespace mbslam

#endif  // MBSLAM_VIEWER_IMAGE_DECODE_H_
