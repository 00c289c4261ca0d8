#ifndef MBSLAM_SERVICES_PERCEPTION_GEOMETRY_CAMERA_H_
#define MBSLAM_SERVICES_PERCEPTION_GEOMETRY_CAMERA_H_

// Pinhole camera with radial-tangential (OpenCV / Brown-Conrady) or equidistant
// fisheye (OpenCV fisheye / Kannala-Brandt) distortion. Pixel coordinates have their
// origin at the centre of the top-left pixel; camera axes x right, y down, z forward.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "common/util/status.h"

namespace mbslam {

enum class DistortionModel { kNone = 0, kRadTan = 1, kFisheye = 2 };

const char* DistortionModelName(DistortionModel model);

struct CameraIntrinsics {
  std::string name = "camera";
  int width = 0;    // px
  int height = 0;   // px
  double fx = 0.0;  // px
  double fy = 0.0;  // px
  double cx = 0.0;  // px
  double cy = 0.0;  // px
  DistortionModel model = DistortionModel::kNone;
  // RADTAN: k1 k2 p1 p2 [k3]; FISHEYE: k1 k2 k3 k4.
  std::vector<double> distortion;

  // Rejects non-finite or non-positive values, wrong coefficient counts, and a
  // principal point far outside the image.
  Status Validate() const;

  Eigen::Matrix3d K() const;
  Eigen::Matrix3d KInverse() const;
  bool HasDistortion() const;

  // Normalised undistorted coordinates (x/z, y/z) -> distorted pixel.
  Eigen::Vector2d NormalizedToPixel(const Eigen::Vector2d& xy) const;
  // Distorted pixel -> normalised undistorted coordinates (iterative inversion).
  Eigen::Vector2d PixelToNormalized(const Eigen::Vector2d& uv) const;

  // Point in the camera frame (z > 0) -> distorted pixel.
  Eigen::Vector2d Project(const Eigen::Vector3d& point_in_cam) const {
    return NormalizedToPixel(point_in_cam.head<2>() / point_in_cam.z());
  }
  // Distorted pixel -> unit bearing in the camera frame.
  Eigen::Vector3d Unproject(const Eigen::Vector2d& uv) const {
    return PixelToNormalized(uv).homogeneous().normalized();
  }

  bool InImage(const Eigen::Vector2d& uv, double border = 0.0) const {
    return uv.x() >= -0.5 + border && uv.y() >= -0.5 + border &&
           uv.x() <= width - 0.5 - border && uv.y() <= height - 0.5 - border;
  }

  // Intrinsics for the image resized by `scale` (e.g. 0.5 for half resolution).
  CameraIntrinsics Scaled(double scale) const;

  // A pinhole model with focal = `focal_factor` * width and the principal point at the
  // image centre (for uncalibrated data such as Hopkins, DAVIS, CamVid).
  static CameraIntrinsics Approximate(int width, int height, double focal_factor = 1.0);
};

// Reads a calibration file with OpenCV / ROS camera_info style fields:
//   camera_name, image_width, image_height,
//   camera_matrix: {rows: 3, cols: 3, data: [fx, 0, cx, 0, fy, cy, 0, 0, 1]},
//   distortion_model: none | radtan | plumb_bob | fisheye | equidistant,
//   distortion_coefficients: {rows: 1, cols: N, data: [...]}
// A leading OpenCV "%YAML:1.0" line is accepted.
Status LoadCameraIntrinsics(const std::string& path, CameraIntrinsics* intrinsics);
Status ParseCameraIntrinsicsYaml(const std::string& text, CameraIntrinsics* intrinsics);
std::string CameraIntrinsicsToYaml(const CameraIntrinsics& intrinsics);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_GEOMETRY_CAMERA_H_
