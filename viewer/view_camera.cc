#include "viewer/view_camera.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace mbslam {
namespace viewer {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Share of the picture's height the 3D view's header may cover (two lines at 720 px).
constexpr double kHeaderFraction = 0.08;

bool Finite(const Eigen::Vector3d& p) { return p.allFinite(); }

// Near and far planes that contain `bounds` seen from the camera, generously.
void FitDepthRange(const Eigen::AlignedBox3d& bounds, ViewCamera* camera) {
  const Eigen::Vector3d center = bounds.center();
  const double radius = std::max(0.5 * bounds.diagonal().norm(), 1e-6);
  const double center_z = (camera->view_from_world * center).z();
  if (camera->orthographic) {
    camera->near = center_z - 4.0 * radius;
    camera->far = center_z + 4.0 * radius;
  } else {
    camera->far = std::max(center_z + 3.0 * radius, 1e-3) * 1.5;
    camera->near = camera->far * 1e-4;
  }
}

Eigen::Vector3d CurrentCameraForward(const Pose& world_from_cam) {
  return world_from_cam.orientation * Eigen::Vector3d::UnitZ();
}

}  // namespace

Eigen::Matrix4d ViewCamera::ClipFromView() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  const double aspect = static_cast<double>(width) / static_cast<double>(height);
  if (orthographic) {
    const double half_h = ortho_half_height, half_w = ortho_half_height * aspect;
    m(0, 0) = 1.0 / half_w;
    m(1, 1) = -1.0 / half_h;  // view y points down, clip y up
    m(2, 2) = 2.0 / (far - near);
    m(2, 3) = -(far + near) / (far - near);
    m(3, 3) = 1.0;
  } else {
    const double f = 1.0 / std::tan(0.5 * fov_y_rad);
    m(0, 0) = f / aspect;
    m(1, 1) = -f;
    m(2, 2) = (far + near) / (far - near);
    m(2, 3) = -2.0 * far * near / (far - near);
    m(3, 2) = 1.0;
  }
  return m;
}

Eigen::Matrix4d ViewCamera::ClipFromWorld() const {
  return ClipFromView() * view_from_world.matrix();
}

bool ViewCamera::Project(const Eigen::Vector3d& point_in_world, Eigen::Vector2d* pixel) const {
  const Eigen::Vector4d clip = ClipFromWorld() * point_in_world.homogeneous();
  if (!(clip.w() > 0.0) || std::abs(clip.z()) > clip.w()) return false;
  const double x = clip.x() / clip.w(), y = clip.y() / clip.w();
  // Window coordinates have pixel centres at +0.5, y up; the PNG's rows are flipped.
  const double u = 0.5 * (x + 1.0) * width - 0.5;
  const double v = height - 0.5 * (y + 1.0) * height - 0.5;
  *pixel = Eigen::Vector2d(u, v);
  return u >= -0.5 && v >= -0.5 && u < width - 0.5 && v < height - 0.5;
}

double ViewCamera::UnitsPerPixel(const Eigen::Vector3d& point_in_world) const {
  if (orthographic) return 2.0 * ortho_half_height / height;
  const double z = std::max((view_from_world * point_in_world).z(), near);
  return 2.0 * z * std::tan(0.5 * fov_y_rad) / height;
}

ViewCamera LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                  const Eigen::Vector3d& up_hint) {
  Eigen::Vector3d z = target - eye;
  if (z.norm() < 1e-12) z = Eigen::Vector3d::UnitZ();
  z.normalize();
  Eigen::Vector3d up = up_hint.norm() > 1e-12 ? up_hint.normalized() : Eigen::Vector3d(0, -1, 0);
  if ((up.cross(z)).norm() < 1e-6) {  // looking straight along "up": any other hint
    up = std::abs(z.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  }
  const Eigen::Vector3d x = (-up).cross(z).normalized();  // x = y cross z with y = -up
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d world_from_view_rotation;
  world_from_view_rotation.col(0) = x;
  world_from_view_rotation.col(1) = y;
  world_from_view_rotation.col(2) = z;
  ViewCamera camera;
  Eigen::Isometry3d world_from_view = Eigen::Isometry3d::Identity();
  world_from_view.linear() = world_from_view_rotation;
  world_from_view.translation() = eye;
  camera.view_from_world = world_from_view.inverse();
  return camera;
}

Eigen::Vector3d UpDirection(const MapData& map) {
  if (map.ground_plane) {
    const Eigen::Vector3d n = map.ground_plane->head<3>();
    if (n.allFinite() && n.norm() > 0.5) return n.normalized();
  }
  return Eigen::Vector3d(0.0, -1.0, 0.0);
}

Eigen::Vector3d Horizontal(const Eigen::Vector3d& direction, const Eigen::Vector3d& up) {
  Eigen::Vector3d h = direction - direction.dot(up) * up;
  if (h.norm() > 1e-6 && h.allFinite()) return h.normalized();
  h = Eigen::Vector3d::UnitZ() - up.z() * up;
  if (h.norm() < 1e-6) h = Eigen::Vector3d::UnitX() - up.x() * up;
  return h.normalized();
}

Eigen::AlignedBox3d SceneBounds(const SceneState& scene, double percentile) {
  Eigen::AlignedBox3d box;  // empty
  const auto& points = scene.map().points;
  if (!points.empty()) {
    std::vector<double> axis[3];
    for (int a = 0; a < 3; ++a) axis[a].reserve(points.size());
    for (const auto& p : points) {
      if (!p.allFinite()) continue;
      for (int a = 0; a < 3; ++a) axis[a].push_back(p[a]);
    }
    if (!axis[0].empty()) {
      const size_t n = axis[0].size();
      const size_t lo = std::min(n - 1, static_cast<size_t>(std::floor(n * percentile / 100.0)));
      const size_t hi = std::max(lo, n - 1 - lo);
      Eigen::Vector3d pmin, pmax;
      for (int a = 0; a < 3; ++a) {
        std::nth_element(axis[a].begin(), axis[a].begin() + lo, axis[a].end());
        pmin[a] = axis[a][lo];
        std::nth_element(axis[a].begin(), axis[a].begin() + hi, axis[a].end());
        pmax[a] = axis[a][hi];
      }
      box.extend(pmin);
      box.extend(pmax);
    }
  }
  auto add = [&box](const Eigen::Vector3d& p) {
    if (Finite(p)) box.extend(p);
  };
  for (const auto& pose : scene.camera_trajectory()) add(pose.world_from_cam.position);
  for (const auto& kf : scene.map().keyframes) add(kf.world_from_cam.position);
  if (scene.current_camera() && HasPose(scene.current_camera()->tracking_state)) {
    add(scene.current_camera()->world_from_cam.position);
  }
  for (const auto& o : scene.objects().objects) {
    if (o.state != ObjectState::kDetected) add(o.position);
    for (const auto& v : o.volumes) add(v.center);
  }
  for (const auto& [id, trajectory] : scene.object_trajectories()) {
    for (const auto& p : trajectory) add(p);
  }
  if (box.isEmpty()) {
    box.extend(Eigen::Vector3d(-1, -1, -1));
    box.extend(Eigen::Vector3d(1, 1, 1));
  }
  // Never degenerate: at least 1% of the largest side (or 1 unit) along every axis.
  const double side = std::max(box.sizes().maxCoeff(), 1e-9);
  const double min_side = side > 1e-6 ? 0.01 * side : 1.0;
  for (int a = 0; a < 3; ++a) {
    if (box.sizes()[a] < min_side) {
      box.min()[a] -= 0.5 * min_side;
      box.max()[a] += 0.5 * min_side;
    }
  }
  return box;
}

double LocalScale(const SceneState& scene, const Eigen::AlignedBox3d& bounds) {
  const auto& cam = scene.current_camera();
  const auto& points = scene.map().points;
  if (cam && HasPose(cam->tracking_state) && !points.empty()) {
    const Eigen::Vector3f c = cam->world_from_cam.position.cast<float>();
    std::vector<float> d;
    d.reserve(points.size());
    for (const auto& p : points) {
      if (p.allFinite()) d.push_back((p - c).norm());
    }
    if (!d.empty()) {
      std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
      const double median = d[d.size() / 2];
      if (median > 1e-9) return median;
    }
  }
  const double diag = bounds.diagonal().norm();
  return diag > 1e-9 ? 0.5 * diag : 1.0;
}

ViewCamera ComputeViewCamera(const View3dOptions& options, const SceneState& scene) {
  const Eigen::Vector3d up = UpDirection(scene.map());
  const Eigen::AlignedBox3d bounds = SceneBounds(scene, options.framing_percentile);
  const double aspect = static_cast<double>(options.width) / options.height;
  const double fov = options.fov_deg * kPi / 180.0;
  ViewCamera camera;

  const auto& current = scene.current_camera();
  const bool have_camera = current && HasPose(current->tracking_state);
  const std::string& mode = options.camera_mode;
  if (mode == "fixed") {
    const Eigen::Vector3d eye(options.fixed_position[0], options.fixed_position[1],
                              options.fixed_position[2]);
    const Eigen::Vector3d target(options.fixed_look_at[0], options.fixed_look_at[1],
                                 options.fixed_look_at[2]);
    const Eigen::Vector3d fixed_up(options.fixed_up[0], options.fixed_up[1], options.fixed_up[2]);
    camera = LookAt(eye, target, fixed_up.norm() > 1e-9 ? fixed_up : up);
    camera.fov_y_rad = fov;
  } else if (mode == "top_down") {
    // Orthographic, looking down along -up; the first camera's forward (world z) points
    // up on the screen, so a forward-moving run goes up the picture.
    const Eigen::Vector3d screen_up = Horizontal(Eigen::Vector3d::UnitZ(), up);
    const Eigen::Vector3d center = bounds.center();
    const double radius = 0.5 * bounds.diagonal().norm();
    camera = LookAt(center + up * (2.0 * radius + 1e-6), center, screen_up);
    camera.orthographic = true;
    double half_w = 0.0, half_h = 0.0;
    const Eigen::Vector3d center_in_view = camera.view_from_world * center;
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3d c =
          camera.view_from_world * bounds.corner(static_cast<Eigen::AlignedBox3d::CornerType>(i));
      half_w = std::max(half_w, std::abs(c.x() - center_in_view.x()));
      half_h = std::max(half_h, std::abs(c.y() - center_in_view.y()));
    }
    // With the legend on, the top of the picture is the header's: the content goes below.
    const double header = options.show_legend ? kHeaderFraction : 0.0;
    const double content = std::max({half_h, half_w / aspect, 1e-6}) * 1.05;
    camera.ortho_half_height = content / (1.0 - header);
    const Eigen::Vector3d shift = screen_up * (header * camera.ortho_half_height);
    const ViewCamera shifted =
        LookAt(center + up * (2.0 * radius + 1e-6) + shift, center + shift, screen_up);
    camera.view_from_world = shifted.view_from_world;
  } else {  // follow, or an overview while there is no camera pose yet
    if (have_camera) {
      const Eigen::Vector3d c = current->world_from_cam.position;
      const Eigen::Vector3d forward = Horizontal(CurrentCameraForward(current->world_from_cam), up);
      const double s = LocalScale(scene, bounds);
      const double back = options.follow_distance > 0.0 ? options.follow_distance : 0.6 * s;
      const double height = options.follow_height > 0.0 ? options.follow_height : 0.45 * s;
      const double ahead = options.follow_look_ahead > 0.0 ? options.follow_look_ahead : 0.6 * s;
      camera = LookAt(c - forward * back + up * height, c + forward * ahead, up);
    } else {
      const Eigen::Vector3d forward = Horizontal(Eigen::Vector3d::UnitZ(), up);
      const Eigen::Vector3d center = bounds.center();
      const double radius = std::max(0.5 * bounds.diagonal().norm(), 1e-6);
      const double distance = radius / std::sin(0.5 * std::min(fov, fov * aspect)) * 1.05;
      const Eigen::Vector3d dir = (-forward + 0.8 * up).normalized();
      camera = LookAt(center + dir * distance, center, up);
    }
    camera.fov_y_rad = fov;
  }
  camera.width = options.width;
  camera.height = options.height;
  // The depth range must also hold the eye's surroundings in follow mode.
  Eigen::AlignedBox3d depth_box = bounds;
  if (have_camera) depth_box.extend(current->world_from_cam.position);
  FitDepthRange(depth_box, &camera);
  return camera;
}

}  // namespace viewer
}  // namespace mbslam
