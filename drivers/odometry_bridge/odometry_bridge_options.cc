#include "drivers/odometry_bridge/odometry_bridge_options.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <iomanip>
#include <sstream>

#include "common/config/options_yaml.h"
#include "common/lcm/channels.h"

namespace mbslam {

bool ExtrinsicOptions::Check() const {
  for (double v : translation) MBSLAM_CHECK_OPTION(std::isfinite(v));
  const double norm = std::sqrt(rotation_wxyz[0] * rotation_wxyz[0] + rotation_wxyz[1] * rotation_wxyz[1] +
                                rotation_wxyz[2] * rotation_wxyz[2] + rotation_wxyz[3] * rotation_wxyz[3]);
  MBSLAM_CHECK_OPTION(std::abs(norm - 1.0) < 1e-3);
  return true;
}

Status ExtrinsicOptions::Resolve(Rigid3d* base_from_cam) const {
  if (!file.empty()) return LoadExtrinsicYaml(file, base_from_cam);
  *base_from_cam = Rigid3d(Eigen::Quaterniond(rotation_wxyz[0], rotation_wxyz[1], rotation_wxyz[2],
                                              rotation_wxyz[3]),
                           Eigen::Vector3d(translation[0], translation[1], translation[2]));
  return Status::Ok();
}

Status LoadExtrinsicYaml(const std::string& path, Rigid3d* base_from_cam) {
  YAML::Node root;
  MBSLAM_RETURN_IF_ERROR(ReadYamlFile(path, &root));
  if (root.IsMap() && root["base_from_cam"]) root = root["base_from_cam"];
  if (!root.IsMap() || !root["translation"] || !root["quaternion"]) {
    return Status::Error(path + ": expected translation: [x, y, z] and quaternion: [w, x, y, z]");
  }
  std::vector<double> t, q;
  MBSLAM_RETURN_IF_ERROR(internal::ParseScalar(root["translation"], "translation", &t).WithContext(path));
  MBSLAM_RETURN_IF_ERROR(internal::ParseScalar(root["quaternion"], "quaternion", &q).WithContext(path));
  if (t.size() != 3 || q.size() != 4) {
    return Status::Error(path + ": translation needs 3 values and quaternion 4 [w, x, y, z]");
  }
  const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
  if (std::abs(rotation.norm() - 1.0) > 1e-3) return Status::Error(path + ": quaternion is not unit");
  *base_from_cam = Rigid3d(rotation, Eigen::Vector3d(t[0], t[1], t[2]));
  return Status::Ok();
}

std::string ExtrinsicToYaml(const Rigid3d& base_from_cam, const std::string& comment) {
  std::ostringstream out;
  out << std::setprecision(12);
  if (!comment.empty()) {
    std::istringstream lines(comment);
    for (std::string line; std::getline(lines, line);) out << "# " << line << "\n";
  }
  const Eigen::Quaterniond& q = base_from_cam.rotation;
  const Eigen::Vector3d& t = base_from_cam.translation;
  out << "base_from_cam:\n"
      << "  translation: [" << t.x() << ", " << t.y() << ", " << t.z() << "]  # camera origin in the base frame (m)\n"
      << "  quaternion: [" << q.w() << ", " << q.x() << ", " << q.y() << ", " << q.z() << "]  # [w, x, y, z]\n";
  return out.str();
}

bool ImageSyncOptions::Check() const {
  MBSLAM_CHECK_OPTION(IsValidChannelName(output_channel));
  MBSLAM_CHECK_OPTION_GT(max_gap_s, 0.0);
  MBSLAM_CHECK_OPTION_GE(max_wait_s, 0.0);
  MBSLAM_CHECK_OPTION_GT(max_pending_images, 0);
  return true;
}

bool OdometryBridgeOptions::Check() const {
  MBSLAM_CHECK_OPTION(input == "dds" || input == "csv" || input == "tum" || input == "lcm");
  MBSLAM_CHECK_OPTION(IsValidChannelName(pose_channel));
  MBSLAM_CHECK_OPTION_GE(speed, 0.0);
  MBSLAM_CHECK_OPTION_GE(max_messages, 0);
  MBSLAM_CHECK_OPTION_GE(idle_timeout_s, 0.0);
  MBSLAM_CHECK_OPTION_SECTION(dds);
  MBSLAM_CHECK_OPTION_SECTION(base_from_cam);
  MBSLAM_CHECK_OPTION_SECTION(image_sync);
  MBSLAM_CHECK_OPTION_SECTION(channels);
  return true;
}

}  // namespace mbslam
