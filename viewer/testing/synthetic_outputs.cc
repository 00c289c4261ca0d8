#include "viewer/testing/synthetic_outputs.h"

#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>

#include "common/lcm/lcm_log.h"

namespace mbslam {
namespace viewer {
namespace testing {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr double kGroundY = 1.5;  // the ground plane y = 1.5 (y points down)

struct Camera {
  Eigen::Matrix3d world_from_cam_rotation;
  Eigen::Vector3d center;
  double fx, fy, cx, cy;
  int width, height;

  // Pixel of a world point; false when behind the camera or outside the image.
  bool Project(const Eigen::Vector3d& p, Eigen::Vector2d* px, double* depth = nullptr) const {
    const Eigen::Vector3d c = world_from_cam_rotation.transpose() * (p - center);
    if (c.z() < 0.3) return false;
    *px = Eigen::Vector2d(fx * c.x() / c.z() + cx, fy * c.y() / c.z() + cy);
    if (depth) *depth = c.z();
    return px->x() >= 0 && px->y() >= 0 && px->x() <= width - 1 && px->y() <= height - 1;
  }
};

struct MovingObject {
  int id;
  int8_t state;
  Eigen::Vector3d start, velocity, half_extent;
  std::vector<Eigen::Vector3d> surface;  // points on the box surface, object frame
  Eigen::Vector3d Position(double t) const { return start + velocity * t; }
};

Camera CameraAt(double t, int width, int height) {
  Camera cam;
  const double yaw = 0.08 * std::sin(0.4 * t);
  cam.world_from_cam_rotation = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
  cam.center = Eigen::Vector3d(0.4 * std::sin(0.5 * t), 0.0, SyntheticOutputs::CameraZ(t));
  cam.fx = cam.fy = 0.8 * width;
  cam.cx = 0.5 * width - 0.5;
  cam.cy = 0.5 * height - 0.5;
  cam.width = width;
  cam.height = height;
  return cam;
}

Eigen::Vector3d CameraVelocity(double t) {
  return Eigen::Vector3d(0.2 * std::cos(0.5 * t), 0.0, 1.2);
}

std::vector<MovingObject> Objects(uint32_t seed) {
  std::mt19937 rng(seed + 17);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<MovingObject> objects(2);
  // A car crossing the street ahead, and a cyclist riding ahead in the camera's own
  // direction (its features move along their epipolar lines: the degenerate case).
  objects[0] = {1,
                2,
                Eigen::Vector3d(-4.5, kGroundY - 0.75, 15.0),
                Eigen::Vector3d(1.1, 0, 0),
                Eigen::Vector3d(2.0, 0.75, 0.9),
                {}};
  objects[1] = {2,
                1,
                Eigen::Vector3d(1.9, kGroundY - 0.9, 6.0),
                Eigen::Vector3d(0, 0, 1.7),
                Eigen::Vector3d(0.35, 0.9, 0.8),
                {}};
  for (MovingObject& o : objects) {
    for (int i = 0; i < 90; ++i) {
      Eigen::Vector3d s(unit(rng), unit(rng), unit(rng));
      const int axis = i % 3;
      s[axis] = s[axis] < 0 ? -1.0 : 1.0;  // on a face
      o.surface.push_back(s.cwiseProduct(o.half_extent));
    }
  }
  return objects;
}

void SetQuaternion(const Eigen::Matrix3d& r, double q[4]) {
  const Eigen::Quaterniond e(r);
  q[0] = e.w();
  q[1] = e.x();
  q[2] = e.y();
  q[3] = e.z();
}

}  // namespace

SyntheticOutputs::SyntheticOutputs(const SyntheticOptions& options) : options_(options) {
  std::mt19937 rng(options.seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  auto add = [&](double x, double y, double z, uint8_t grey) {
    static_points_.push_back({static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)});
    const uint8_t tint = static_cast<uint8_t>(20 * u01(rng));
    static_colors_.push_back(
        {static_cast<uint8_t>(grey + tint), grey, static_cast<uint8_t>(grey - tint / 2)});
  };
  for (int i = 0; i < 1500; ++i) add(-6 + 12 * u01(rng), kGroundY, -2 + 45 * u01(rng), 110);
  for (double side : {-5.5, 5.5}) {
    for (int i = 0; i < 900; ++i) add(side, kGroundY - 5.0 * u01(rng), 45 * u01(rng), 170);
  }
  for (int post = 0; post < 8; ++post) {
    for (int i = 0; i < 25; ++i) {
      add(post % 2 ? 3.8 : -3.8, kGroundY - 2.5 * i / 24.0, 4.0 + 5.0 * post, 60);
    }
  }
}

SyntheticFrame SyntheticOutputs::Frame(int k) const {
  const SyntheticOptions& o = options_;
  const double t = k / o.fps, t_prev = (k - 1) / o.fps;
  SyntheticFrame f;
  f.utime = o.start_utime + static_cast<int64_t>(std::llround(t * 1e6));
  const int8_t scale =
      o.metric ? mbslam::camera_pose_t::SCALE_METRIC : mbslam::camera_pose_t::SCALE_UP_TO_SCALE;
  const Camera cam = CameraAt(t, o.width, o.height);
  const Camera prev = CameraAt(t_prev, o.width, o.height);
  const std::vector<MovingObject> movers = Objects(o.seed);

  // Pose.
  f.pose.utime = f.utime;
  f.pose.frame_seq = k;
  for (int i = 0; i < 3; ++i) f.pose.position[i] = cam.center[i];
  SetQuaternion(cam.world_from_cam_rotation, f.pose.orientation);
  f.pose.tracking_state =
      k < 2 ? mbslam::camera_pose_t::TRACKING_INITIALIZING : mbslam::camera_pose_t::TRACKING_OK;
  f.pose.scale_state = scale;
  f.pose.scale_to_metric = o.metric ? 1.0 : 0.0;
  f.pose.num_keyframes = k / 5 + 1;

  // Image: sky, ground, facade dots, static points as blobs, objects as filled boxes.
  cv::Mat image(o.height, o.width, CV_8UC3);
  const int horizon = static_cast<int>(cam.cy);
  image(cv::Rect(0, 0, o.width, std::max(1, horizon))).setTo(cv::Scalar(230, 200, 170));
  image(cv::Rect(0, horizon, o.width, o.height - horizon)).setTo(cv::Scalar(105, 110, 110));
  for (size_t i = 0; i < static_points_.size(); ++i) {
    const auto& p = static_points_[i];
    Eigen::Vector2d px;
    double depth = 0;
    if (!cam.Project(Eigen::Vector3d(p[0], p[1], p[2]), &px, &depth)) continue;
    const auto& c = static_colors_[i];
    cv::circle(image, cv::Point(static_cast<int>(px.x()), static_cast<int>(px.y())),
               std::max(1, static_cast<int>(8.0 / depth)), cv::Scalar(c[2], c[1], c[0]),
               cv::FILLED);
  }
  struct Projected {
    int body_id;
    Eigen::Vector2d px, prev_px;
    bool has_prev;
    double depth;
    float epipolar_px;
  };
  std::vector<Projected> features;
  std::vector<std::vector<cv::Point2f>> hulls(movers.size());
  for (size_t m = 0; m < movers.size(); ++m) {
    const MovingObject& mo = movers[m];
    std::vector<cv::Point> corners;
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3d s((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
      Eigen::Vector2d px;
      const Eigen::Vector3d p = mo.Position(t) + s.cwiseProduct(mo.half_extent);
      const Eigen::Vector3d c = cam.world_from_cam_rotation.transpose() * (p - cam.center);
      if (c.z() < 0.3) continue;
      px = Eigen::Vector2d(cam.fx * c.x() / c.z() + cam.cx, cam.fy * c.y() / c.z() + cam.cy);
      corners.emplace_back(static_cast<int>(px.x()), static_cast<int>(px.y()));
    }
    if (corners.size() >= 3) {
      std::vector<cv::Point> hull;
      cv::convexHull(corners, hull);
      cv::fillConvexPoly(image, hull, m == 0 ? cv::Scalar(40, 40, 160) : cv::Scalar(150, 60, 30));
    }
    for (const Eigen::Vector3d& s : mo.surface) {
      Projected p;
      p.body_id = mo.id;
      if (!cam.Project(mo.Position(t) + s, &p.px, &p.depth)) continue;
      p.has_prev = prev.Project(mo.Position(t_prev) + s, &p.prev_px) && k > 0;
      p.epipolar_px = m == 0 ? 9.0f : 0.8f;
      features.push_back(p);
      hulls[m].emplace_back(static_cast<float>(p.px.x()), static_cast<float>(p.px.y()));
    }
  }
  for (size_t i = 0; i < static_points_.size(); i += 4) {
    const auto& q = static_points_[i];
    const Eigen::Vector3d p(q[0], q[1], q[2]);
    Projected f0;
    f0.body_id = (i / 4) % 23 == 0 ? -1 : 0;
    if (!cam.Project(p, &f0.px, &f0.depth)) continue;
    f0.has_prev = prev.Project(p, &f0.prev_px) && k > 0;
    f0.epipolar_px = 0.3f;
    features.push_back(f0);
  }

  // Tracks, with occlusion for static features inside a nearer object's hull.
  f.tracks.utime = f.utime;
  f.tracks.frame_seq = k;
  f.tracks.width = o.width;
  f.tracks.height = o.height;
  const Eigen::Vector3d e = cam.world_from_cam_rotation.transpose() * CameraVelocity(t);
  f.tracks.epipole[0] = cam.fx * e.x() + cam.cx * e.z();
  f.tracks.epipole[1] = cam.fy * e.y() + cam.cy * e.z();
  f.tracks.epipole[2] = e.z();
  std::vector<std::vector<cv::Point2f>> hull_polygons(movers.size());
  for (size_t m = 0; m < movers.size(); ++m) {
    if (hulls[m].size() >= 3) cv::convexHull(hulls[m], hull_polygons[m]);
  }
  int64_t id = 0;
  int occluded_seen = 0;
  for (const Projected& p : features) {
    mbslam::feature_track_t tr{};
    tr.id = ++id;
    tr.u = static_cast<float>(p.px.x());
    tr.v = static_cast<float>(p.px.y());
    tr.prev_u = p.has_prev ? static_cast<float>(p.prev_px.x()) : kNaN;
    tr.prev_v = p.has_prev ? static_cast<float>(p.prev_px.y()) : kNaN;
    tr.age = p.has_prev ? 2 + k % 7 : 1;
    tr.body_id = p.body_id;
    tr.p_static = p.body_id == 0 ? 0.95f : p.body_id > 0 ? 0.05f : 0.5f;
    tr.epipolar_px = p.epipolar_px;
    tr.fvb = p.body_id == 0 ? 0.9f : 0.1f;
    tr.flags = p.has_prev ? 0 : mbslam::feature_track_t::FLAG_NEW;
    if (p.body_id == 0) {
      tr.flags |= mbslam::feature_track_t::FLAG_HAS_3D;
      for (size_t m = 0; m < movers.size(); ++m) {
        if (hull_polygons[m].size() < 3) continue;
        const double object_depth =
            (cam.world_from_cam_rotation.transpose() * (movers[m].Position(t) - cam.center)).z();
        if (object_depth < p.depth &&
            cv::pointPolygonTest(hull_polygons[m], cv::Point2f(tr.u, tr.v), false) > 0) {
          tr.flags |= mbslam::feature_track_t::FLAG_OCCLUDED;
        }
      }
      // Most static points behind an object are simply not tracked any more.
      if ((tr.flags & mbslam::feature_track_t::FLAG_OCCLUDED) && occluded_seen++ % 5 != 0) {
        --id;
        continue;
      }
    }
    f.tracks.tracks.push_back(tr);
  }
  f.tracks.num_tracks = static_cast<int32_t>(f.tracks.tracks.size());
  for (size_t m = 0; m < movers.size(); ++m) {
    if (hull_polygons[m].size() < 3) continue;
    mbslam::image_hull_t h{};
    h.body_id = movers[m].id;
    for (const auto& p : hull_polygons[m]) {
      h.u.push_back(p.x);
      h.v.push_back(p.y);
    }
    h.num_points = static_cast<int32_t>(h.u.size());
    f.tracks.hulls.push_back(h);
  }
  f.tracks.num_hulls = static_cast<int32_t>(f.tracks.hulls.size());

  // Objects with particles and predicted volumes over 1 s.
  f.objects.utime = f.utime;
  f.objects.frame_seq = k;
  f.objects.scale_state = scale;
  std::mt19937 rng(o.seed * 1000u + static_cast<uint32_t>(k));
  std::normal_distribution<double> normal(0.0, 1.0);
  for (const MovingObject& mo : movers) {
    mbslam::object_t ob{};
    ob.id = mo.id;
    ob.state = mo.state;
    ob.first_seen_utime = o.start_utime;
    ob.num_tracks = static_cast<int32_t>(mo.surface.size());
    const Eigen::Vector3d pos = mo.Position(t);
    for (int i = 0; i < 3; ++i) {
      ob.position[i] = pos[i];
      ob.linear_velocity[i] = mo.velocity[i];
      ob.extent[i] = 2.0 * mo.half_extent[i];
    }
    ob.orientation[0] = 1.0;
    ob.depth = (cam.world_from_cam_rotation.transpose() * (pos - cam.center)).z();
    ob.depth_sigma = 0.1 * ob.depth;
    ob.relative_scale = mo.state == 2 ? 1.0 : 0.0;
    ob.num_particles = 500;
    ob.effective_sample_size = 320.0;
    for (int i = 0; i < 60; ++i) {
      const Eigen::Vector3d ray = (pos - cam.center).normalized();
      const Eigen::Vector3d p =
          pos + ray * (0.25 * ob.depth * 0.3 * normal(rng)) +
          Eigen::Vector3d(0.15 * normal(rng), 0.05 * normal(rng), 0.15 * normal(rng));
      ob.particle_samples.push_back(
          {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())});
    }
    ob.num_particle_samples = static_cast<int32_t>(ob.particle_samples.size());
    if (mo.state == 2) {
      for (const Eigen::Vector3d& s : mo.surface) {
        const Eigen::Vector3d p = pos + s;
        ob.points.push_back(
            {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())});
      }
    }
    ob.num_points = static_cast<int32_t>(ob.points.size());
    for (int h = 0; h <= 4; ++h) {
      mbslam::predicted_volume_t v{};
      v.horizon_us = h * 250000;
      v.utime = f.utime + v.horizon_us;
      const Eigen::Vector3d c = pos + mo.velocity * (0.25 * h);
      for (int i = 0; i < 3; ++i) {
        v.center[i] = c[i];
        v.half_extent[i] = mo.half_extent[i] * (1.0 + 0.08 * h);
      }
      v.orientation[0] = 1.0;
      v.probability = 0.95;
      ob.volumes.push_back(v);
    }
    ob.num_volumes = static_cast<int32_t>(ob.volumes.size());
    ob.hull.body_id = mo.id;
    f.objects.objects.push_back(ob);
  }
  f.objects.num_objects = static_cast<int32_t>(f.objects.objects.size());

  // Image message.
  f.image.utime = f.utime;
  f.image.seq = k;
  f.image.camera_name = "synthetic";
  f.image.width = o.width;
  f.image.height = o.height;
  if (o.jpeg) {
    std::vector<uint8_t> bytes;
    cv::imencode(".jpg", image, bytes, {cv::IMWRITE_JPEG_QUALITY, 85});
    f.image.encoding = mbslam::image_t::ENCODING_JPEG;
    f.image.row_stride = 0;
    f.image.data = bytes;
  } else {
    f.image.encoding = mbslam::image_t::ENCODING_BGR8;
    f.image.row_stride = o.width * 3;
    f.image.data.assign(image.data, image.data + image.total() * 3);
  }
  f.image.size = static_cast<int32_t>(f.image.data.size());

  // Map and occupancy every map_every frames: the points seen so far.
  if (o.map_every > 0 && k % o.map_every == 0) {
    mbslam::map_t map{};
    map.utime = f.utime;
    map.scale_state = scale;
    octomap::OcTree tree(0.5);
    for (size_t i = 0; i < static_points_.size(); ++i) {
      const auto& p = static_points_[i];
      if (p[2] > cam.center.z() + 20.0 || p[2] < cam.center.z() - 15.0) continue;
      map.point_ids.push_back(static_cast<int64_t>(i));
      map.points.push_back({p[0], p[1], p[2]});
      map.colors.push_back({static_colors_[i][0], static_colors_[i][1], static_colors_[i][2]});
      if (i % 2 == 0) tree.updateNode(octomap::point3d(p[0], p[1], p[2]), true);
    }
    map.num_points = static_cast<int32_t>(map.points.size());
    for (int kf = 0; kf <= k; kf += 5) {
      const Camera c = CameraAt(kf / o.fps, o.width, o.height);
      mbslam::keyframe_t key{};
      key.id = kf / 5;
      key.utime = o.start_utime + static_cast<int64_t>(std::llround(kf / o.fps * 1e6));
      for (int i = 0; i < 3; ++i) key.position[i] = c.center[i];
      SetQuaternion(c.world_from_cam_rotation, key.orientation);
      key.num_observations = 200;
      map.keyframes.push_back(key);
    }
    map.num_keyframes = static_cast<int32_t>(map.keyframes.size());
    map.ground_plane[0] = 0.0;
    map.ground_plane[1] = -1.0;
    map.ground_plane[2] = 0.0;
    map.ground_plane[3] = kGroundY;
    f.map = map;

    mbslam::occupancy_t occ{};
    occ.utime = f.utime;
    occ.frame_id = "world";
    occ.scale_state = scale;
    occ.resolution = tree.getResolution();
    tree.prune();
    std::ostringstream out;
    tree.writeBinary(out);
    const std::string bytes = out.str();
    occ.data.assign(bytes.begin(), bytes.end());
    occ.size = static_cast<int32_t>(occ.data.size());
    int32_t occupied = 0;
    for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
      if (tree.isNodeOccupied(*it)) ++occupied;
    }
    occ.num_occupied = occupied;
    occ.memory_bytes = static_cast<int64_t>(tree.memoryUsage());
    f.occupancy = occ;
  }
  return f;
}

Status WriteSyntheticLog(const std::string& path, const SyntheticOptions& options,
                         const ChannelOptions& channels, bool faults, int* bad_messages_written) {
  Status status;
  auto log = LcmLogWriter::Open(path, &status);
  if (!log) return status;
  const SyntheticOutputs outputs(options);
  int bad = 0;
  for (int k = 0; k < options.frames; ++k) {
    const SyntheticFrame f = outputs.Frame(k);
    MBSLAM_RETURN_IF_ERROR(log->Write(channels.camera_image, f.utime, f.image));
    MBSLAM_RETURN_IF_ERROR(log->Write(channels.perception_camera_pose, f.utime, f.pose));
    MBSLAM_RETURN_IF_ERROR(log->Write(channels.perception_tracks, f.utime, f.tracks));
    MBSLAM_RETURN_IF_ERROR(log->Write(channels.perception_objects, f.utime, f.objects));
    if (f.map) MBSLAM_RETURN_IF_ERROR(log->Write(channels.perception_map, f.utime, *f.map));
    if (f.occupancy) {
      MBSLAM_RETURN_IF_ERROR(log->Write(channels.perception_occupancy, f.utime, *f.occupancy));
    }
    if (!faults) continue;
    auto encode = [](const auto& msg) {
      std::vector<uint8_t> buf(static_cast<size_t>(msg.getEncodedSize()));
      msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
      return buf;
    };
    if (k == 5 && f.map) {  // a truncated map
      const std::vector<uint8_t> buf = encode(*f.map);
      MBSLAM_RETURN_IF_ERROR(
          log->WriteRaw(channels.perception_map, f.utime, buf.data(), buf.size() / 2));
      ++bad;
    }
    if (k == 6) {  // garbage on the objects channel
      std::mt19937 rng(k);
      std::vector<uint8_t> junk(64);
      for (auto& b : junk) b = static_cast<uint8_t>(rng());
      MBSLAM_RETURN_IF_ERROR(
          log->WriteRaw(channels.perception_objects, f.utime, junk.data(), junk.size()));
      ++bad;
    }
    if (k == 7) {  // a camera pose on the tracks channel (wrong fingerprint)
      MBSLAM_RETURN_IF_ERROR(log->Write(channels.perception_tracks, f.utime, f.pose));
      ++bad;
    }
    if (k == 9) {  // tracks whose length field claims two billion tracks
      std::vector<uint8_t> buf = encode(f.tracks);
      // Fingerprint (8) + utime (8) + frame_seq (8) + width (4) + height (4) + epipole (24).
      const size_t at = 8 + 8 + 8 + 4 + 4 + 24;
      buf[at] = 0x7f;
      buf[at + 1] = buf[at + 2] = buf[at + 3] = 0xff;
      MBSLAM_RETURN_IF_ERROR(
          log->WriteRaw(channels.perception_tracks, f.utime, buf.data(), buf.size()));
      ++bad;
    }
    if (k == 11) {  // a pose that decodes but is not a pose
      mbslam::camera_pose_t nan_pose = f.pose;
      nan_pose.position[0] = std::numeric_limits<double>::quiet_NaN();
      MBSLAM_RETURN_IF_ERROR(log->Write(channels.perception_camera_pose, f.utime, nan_pose));
      ++bad;
    }
  }
  log->Flush();
  if (bad_messages_written) *bad_messages_written = bad;
  return Status::Ok();
}

}  // namespace testing
}  // namespace viewer
}  // namespace mbslam
