#include "drivers/camera/camera_driver_options.h"

#include "drivers/common/pose_files.h"

namespace mbslam {

bool IsKnownCameraSource(const std::string& s) {
  return s == "dc1394" || s == "v4l2" || s == "video" || s == "folder" || s == "tum" ||
         s == "kitti" || s == "tartanair" || s == "sequence";
}

bool IsLiveCameraSource(const std::string& s) { return s == "dc1394" || s == "v4l2"; }

bool ImageOutputOptions::Check() const {
  MBSLAM_CHECK_OPTION(encoding == "raw" || encoding == "jpeg" || encoding == "png" ||
                      encoding == "source");
  MBSLAM_CHECK_OPTION(color == "keep" || color == "gray" || color == "bgr");
  MBSLAM_CHECK_OPTION_GE(jpeg_quality, 0);
  MBSLAM_CHECK_OPTION_LE(jpeg_quality, 100);
  MBSLAM_CHECK_OPTION_GE(png_compression, 0);
  MBSLAM_CHECK_OPTION_LE(png_compression, 9);
  return true;
}

bool PlaybackOptions::Check() const {
  MBSLAM_CHECK_OPTION_GE(speed, 0.0);
  MBSLAM_CHECK_OPTION_GE(start_frame, 0);
  MBSLAM_CHECK_OPTION(end_frame < 0 || end_frame > start_frame);
  MBSLAM_CHECK_OPTION_GE(start_s, 0.0);
  MBSLAM_CHECK_OPTION(end_s < 0.0 || end_s > start_s);
  MBSLAM_CHECK_OPTION_GE(loops, 0);
  return true;
}

bool FolderOptions::Check() const {
  MBSLAM_CHECK_OPTION_GT(rate_hz, 0.0);
  MBSLAM_CHECK_OPTION_GE(time_origin_s, 0.0);
  MBSLAM_CHECK_OPTION(IsValidTimeUnit(timestamps_unit));
  MBSLAM_CHECK_OPTION(!extensions.empty());
  MBSLAM_CHECK_OPTION_GE(kitti_camera, 0);
  MBSLAM_CHECK_OPTION_LE(kitti_camera, 3);
  return true;
}

bool GroundTruthOptions::Check() const {
  MBSLAM_CHECK_OPTION(format == "tum" || format == "kitti" || format == "tartanair");
  MBSLAM_CHECK_OPTION_GT(max_gap_s, 0.0);
  return true;
}

bool Dc1394Options::Check() const {
  MBSLAM_CHECK_OPTION_GT(framerate, 0.0);
  MBSLAM_CHECK_OPTION(iso_speed == 100 || iso_speed == 200 || iso_speed == 400 ||
                      iso_speed == 800 || iso_speed == 1600 || iso_speed == 3200);
  MBSLAM_CHECK_OPTION_GE(dma_buffers, 2);
  MBSLAM_CHECK_OPTION_LE(dma_buffers, 64);
  MBSLAM_CHECK_OPTION(bayer_pattern == "none" || bayer_pattern == "RGGB" ||
                      bayer_pattern == "GBRG" || bayer_pattern == "GRBG" ||
                      bayer_pattern == "BGGR");
  MBSLAM_CHECK_OPTION_GT(frame_timeout_s, 0.0);
  return true;
}

bool V4l2Options::Check() const {
  MBSLAM_CHECK_OPTION(!device.empty());
  MBSLAM_CHECK_OPTION_GE(width, 0);
  MBSLAM_CHECK_OPTION_GE(height, 0);
  MBSLAM_CHECK_OPTION_GE(fps, 0.0);
  MBSLAM_CHECK_OPTION(fourcc.empty() || fourcc.size() == 4);
  MBSLAM_CHECK_OPTION_GT(frame_timeout_s, 0.0);
  return true;
}

bool LiveOptions::Check() const {
  MBSLAM_CHECK_OPTION_GT(reconnect_interval_s, 0.0);
  MBSLAM_CHECK_OPTION_GE(max_reconnect_attempts, 0);
  return true;
}

bool CameraDriverOptions::Check() const {
  MBSLAM_CHECK_OPTION(IsKnownCameraSource(source));
  MBSLAM_CHECK_OPTION_GE(calibration_period_s, 0.0);
  MBSLAM_CHECK_OPTION_SECTION(image);
  MBSLAM_CHECK_OPTION_SECTION(playback);
  MBSLAM_CHECK_OPTION_SECTION(folder);
  MBSLAM_CHECK_OPTION_SECTION(ground_truth);
  MBSLAM_CHECK_OPTION_SECTION(dc1394);
  MBSLAM_CHECK_OPTION_SECTION(v4l2);
  MBSLAM_CHECK_OPTION_SECTION(live);
  MBSLAM_CHECK_OPTION_SECTION(channels);
  return true;
}

}  // namespace mbslam
