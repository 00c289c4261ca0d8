#ifndef MBSLAM_DRIVERS_CAMERA_CAMERA_MESSAGES_H_
#define MBSLAM_DRIVERS_CAMERA_CAMERA_MESSAGES_H_

// Frames, calibrations and ground truth to and from the LCM message types.

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>

#include "common/util/status.h"
#include "drivers/camera/camera_driver_options.h"
#include "drivers/camera/frame_source.h"
#include "mbslam/camera_calibration_t.hpp"
#include "mbslam/ground_truth_t.hpp"
#include "mbslam/image_t.hpp"
#include "services/perception/geometry/camera.h"

namespace mbslam {

// Fills width, height, row_stride, encoding, size and data of `msg` from a frame
// according to the output options (utime, seq and camera_name are left to the caller).
Status EncodeFrameImage(const Frame& frame, const ImageOutputOptions& options,
                        mbslam::image_t* msg);

// Decodes an image_t (any encoding) into an 8-bit gray or BGR image; RGB8 becomes BGR.
// Checks that the sizes in the message agree with each other.
Status DecodeImageMessage(const mbslam::image_t& msg, cv::Mat* image);

void FillCalibrationMessage(const CameraIntrinsics& intrinsics, int64_t utime,
                            const std::string& camera_name, mbslam::camera_calibration_t* msg);

// The frame's truth: camera pose (has_camera = 0 when missing) and bodies.
void FillGroundTruthMessage(const Frame& frame, int64_t seq, mbslam::ground_truth_t* msg);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_CAMERA_CAMERA_MESSAGES_H_
