#ifndef MBSLAM_DRIVERS_CAMERA_DC1394_MODES_H_
#define MBSLAM_DRIVERS_CAMERA_DC1394_MODES_H_

// libdc1394 names and frame conversion, separate from the camera handling so they can
// be tested without a camera.

#include <dc1394/dc1394.h>
#include <opencv2/core.hpp>

#include <string>

#include "common/util/status.h"

namespace mbslam {

// "640x480_MONO8", "1024x768_YUV422", "FORMAT7_0", ... (case-insensitive).
Status ParseDc1394VideoMode(const std::string& name, dc1394video_mode_t* mode);
std::string Dc1394VideoModeName(dc1394video_mode_t mode);
bool IsDc1394Format7(dc1394video_mode_t mode);

// 1.875 3.75 7.5 15 30 60 120 240 Hz.
Status ParseDc1394Framerate(double hz, dc1394framerate_t* rate);
double Dc1394FramerateHz(dc1394framerate_t rate);

// 100 ... 3200 Mb/s.
Status ParseDc1394IsoSpeed(int mbps, dc1394speed_t* speed);

// MONO8, MONO16, RAW8, RAW16, RGB8, RGB16, YUV411, YUV422, YUV444.
Status ParseDc1394ColorCoding(const std::string& name, dc1394color_coding_t* coding);
std::string Dc1394ColorCodingName(dc1394color_coding_t coding);

// "0x00b09d0100a1b2c3" or decimal.
Status ParseDc1394Guid(const std::string& text, uint64_t* guid);
std::string FormatDc1394Guid(uint64_t guid);

// Converts a captured frame to an 8-bit gray or BGR image (a copy). `bayer_pattern`
// ("none", "RGGB", ...) demosaics MONO8 / RAW8 data; RAW8 with "none" uses the
// frame's own colour filter. 16-bit data keeps its top 8 significant bits.
Status ConvertDc1394Frame(const dc1394video_frame_t& frame, const std::string& bayer_pattern,
                          cv::Mat* image);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_CAMERA_DC1394_MODES_H_
