#include "services/perception/geometry/camera.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/LU>

#include <cmath>
#include <sstream>

#include "common/config/options_yaml.h"
#include "common/util/atomic_file.h"

namespace mbslam {

const char* DistortionModelName(DistortionModel model) {
  switch (model) {
    case DistortionModel::kNone: return "none";
    case DistortionModel::kRadTan: return "radtan";
    case DistortionModel::kFisheye: return "fisheye";
  }
  return "unknown";
}

Status CameraIntrinsics::Validate() const {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    return Status::Error("camera '" + name + "': image size " + std::to_string(width) + "x" +
                         std::to_string(height) + " is not plausible");
  }
  for (double v : {fx, fy, cx, cy}) {
    if (!std::isfinite(v)) return Status::Error("camera '" + name + "': non-finite intrinsics");
  }
  if (fx <= 0.0 || fy <= 0.0) {
    return Status::Error("camera '" + name + "': focal lengths must be positive");
  }
  if (cx < -width || cx > 2.0 * width || cy < -height || cy > 2.0 * height) {
    return Status::Error("camera '" + name + "': principal point far outside the image");
  }
  for (double d : distortion) {
    if (!std::isfinite(d)) {
      return Status::Error("camera '" + name + "': non-finite distortion coefficient");
    }
  }
  switch (model) {
    case DistortionModel::kNone:
      for (double d : distortion) {
        if (d != 0.0) return Status::Error("camera '" + name + "': model none with coefficients");
      }
      break;
    case DistortionModel::kRadTan:
      if (distortion.size() != 4 && distortion.size() != 5) {
        return Status::Error("camera '" + name + "': radtan needs 4 or 5 coefficients, got " +
                             std::to_string(distortion.size()));
      }
      break;
    case DistortionModel::kFisheye:
      if (distortion.size() != 4) {
        return Status::Error("camera '" + name + "': fisheye needs 4 coefficients, got " +
                             std::to_string(distortion.size()));
      }
      break;
  }
  return Status::Ok();
}

Eigen::Matrix3d CameraIntrinsics::K() const {
  Eigen::Matrix3d k;
  k << fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0;
  return k;
}

Eigen::Matrix3d CameraIntrinsics::KInverse() const {
  Eigen::Matrix3d k;
  k << 1.0 / fx, 0.0, -cx / fx, 0.0, 1.0 / fy, -cy / fy, 0.0, 0.0, 1.0;
  return k;
}

bool CameraIntrinsics::HasDistortion() const {
  if (model == DistortionModel::kNone) return false;
  for (double d : distortion) {
    if (d != 0.0) return true;
  }
  return false;
}

namespace {

Eigen::Vector2d Distort(const CameraIntrinsics& c, const Eigen::Vector2d& xy) {
  const double x = xy.x();
  const double y = xy.y();
  if (c.model == DistortionModel::kRadTan) {
    const double k1 = c.distortion[0], k2 = c.distortion[1], p1 = c.distortion[2],
                 p2 = c.distortion[3];
    const double k3 = c.distortion.size() > 4 ? c.distortion[4] : 0.0;
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
    return Eigen::Vector2d(x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
                           y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y);
  }
  if (c.model == DistortionModel::kFisheye) {
    const double r = std::sqrt(x * x + y * y);
    if (r < 1e-12) return xy;
    const double theta = std::atan(r);
    const double t2 = theta * theta;
    const double theta_d =
        theta * (1.0 + t2 * (c.distortion[0] +
                             t2 * (c.distortion[1] + t2 * (c.distortion[2] + t2 * c.distortion[3]))));
    return xy * (theta_d / r);
  }
  return xy;
}

}  // namespace

Eigen::Vector2d CameraIntrinsics::NormalizedToPixel(const Eigen::Vector2d& xy) const {
  const Eigen::Vector2d d = HasDistortion() ? Distort(*this, xy) : xy;
  return Eigen::Vector2d(fx * d.x() + cx, fy * d.y() + cy);
}

Eigen::Vector2d CameraIntrinsics::PixelToNormalized(const Eigen::Vector2d& uv) const {
  const Eigen::Vector2d distorted((uv.x() - cx) / fx, (uv.y() - cy) / fy);
  if (!HasDistortion()) return distorted;
  // Gauss-Newton on Distort(xy) = distorted with a numerical Jacobian; converges in a
  // few steps for physical lenses.
  Eigen::Vector2d xy = distorted;
  for (int iter = 0; iter < 20; ++iter) {
    const Eigen::Vector2d f = Distort(*this, xy) - distorted;
    if (f.squaredNorm() < 1e-24) break;
    constexpr double h = 1e-7;
    Eigen::Matrix2d J;
    J.col(0) = (Distort(*this, xy + Eigen::Vector2d(h, 0.0)) - Distort(*this, xy)) / h;
    J.col(1) = (Distort(*this, xy + Eigen::Vector2d(0.0, h)) - Distort(*this, xy)) / h;
    const Eigen::Vector2d step = J.partialPivLu().solve(f);
    if (!step.allFinite()) break;
    xy -= step;
  }
  return xy;
}

CameraIntrinsics CameraIntrinsics::Scaled(double scale) const {
  CameraIntrinsics out = *this;
  out.width = static_cast<int>(std::lround(width * scale));
  out.height = static_cast<int>(std::lround(height * scale));
  out.fx = fx * scale;
  out.fy = fy * scale;
  // Pixel centres: u' + 0.5 = (u + 0.5) * scale.
  out.cx = (cx + 0.5) * scale - 0.5;
  out.cy = (cy + 0.5) * scale - 0.5;
  return out;
}

CameraIntrinsics CameraIntrinsics::Approximate(int width, int height, double focal_factor) {
  CameraIntrinsics c;
  c.name = "approximate";
  c.width = width;
  c.height = height;
  c.fx = c.fy = focal_factor * width;
  c.cx = (width - 1) * 0.5;
  c.cy = (height - 1) * 0.5;
  return c;
}

namespace {

Status ReadMatrixData(const YAML::Node& node, const std::string& name, std::vector<double>* data) {
  if (!node.IsDefined()) return Status::Error("missing '" + name + "'");
  const YAML::Node values = node.IsMap() ? node["data"] : node;
  return internal::ParseScalar(values, name, data);
}

}  // namespace

Status ParseCameraIntrinsicsYaml(const std::string& text, CameraIntrinsics* intrinsics) {
  MBSLAM_RETURN_IF_ERROR(CheckYamlTextIsUtf8(text, "calibration"));
  std::string body = text;
  if (body.rfind("%YAML:", 0) == 0) body = body.substr(body.find('\n') + 1);
  YAML::Node root;
  try {
    root = YAML::Load(body);
  } catch (const YAML::Exception& e) {
    return Status::Error(std::string("calibration: YAML syntax error: ") + e.what());
  }
  if (!root.IsMap()) return Status::Error("calibration: expected a mapping");
  CameraIntrinsics c;
  try {
    if (root["camera_name"]) c.name = root["camera_name"].as<std::string>();
    MBSLAM_RETURN_IF_ERROR(internal::ParseScalar(root["image_width"], "image_width", &c.width));
    MBSLAM_RETURN_IF_ERROR(internal::ParseScalar(root["image_height"], "image_height", &c.height));
    std::vector<double> k;
    MBSLAM_RETURN_IF_ERROR(ReadMatrixData(root["camera_matrix"], "camera_matrix", &k));
    if (k.size() != 9) return Status::Error("calibration: camera_matrix needs 9 values");
    c.fx = k[0];
    c.cx = k[2];
    c.fy = k[4];
    c.cy = k[5];
    std::string model = "none";
    if (root["distortion_model"]) model = root["distortion_model"].as<std::string>();
    if (model == "none" || model == "pinhole") {
      c.model = DistortionModel::kNone;
    } else if (model == "radtan" || model == "plumb_bob" || model == "rational_polynomial") {
      c.model = DistortionModel::kRadTan;
    } else if (model == "fisheye" || model == "equidistant") {
      c.model = DistortionModel::kFisheye;
    } else {
      return Status::Error("calibration: unknown distortion_model '" + model + "'");
    }
    if (root["distortion_coefficients"]) {
      MBSLAM_RETURN_IF_ERROR(ReadMatrixData(root["distortion_coefficients"],
                                            "distortion_coefficients", &c.distortion));
    }
    // An all-zero radtan vector is the same as no distortion.
    if (c.model == DistortionModel::kNone) c.distortion.clear();
  } catch (const YAML::Exception& e) {
    return Status::Error(std::string("calibration: ") + e.what());
  }
  MBSLAM_RETURN_IF_ERROR(c.Validate());
  *intrinsics = c;
  return Status::Ok();
}

Status LoadCameraIntrinsics(const std::string& path, CameraIntrinsics* intrinsics) {
  std::string text;
  MBSLAM_RETURN_IF_ERROR(ReadFileToString(path, &text, size_t{1} << 20));
  return ParseCameraIntrinsicsYaml(text, intrinsics).WithContext(path);
}

std::string CameraIntrinsicsToYaml(const CameraIntrinsics& c) {
  std::ostringstream out;
  out.precision(17);
  out << "camera_name: " << internal::FormatScalar(c.name) << "\n"
      << "image_width: " << c.width << "\n"
      << "image_height: " << c.height << "\n"
      << "camera_matrix: {rows: 3, cols: 3, data: [" << c.fx << ", 0, " << c.cx << ", 0, " << c.fy
      << ", " << c.cy << ", 0, 0, 1]}\n"
      << "distortion_model: " << DistortionModelName(c.model) << "\n"
      << "distortion_coefficients: {rows: 1, cols: " << c.distortion.size() << ", data: [";
  for (size_t i = 0; i < c.distortion.size(); ++i) out << (i ? ", " : "") << c.distortion[i];
  out << "]}\n";
  return out.str();
}

}  // namespace mbslam
