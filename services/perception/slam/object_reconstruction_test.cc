#include "services/perception/slam/object_reconstruction.h"

#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace mbslam {
namespace {

// A rigid box of points passing in front of a still camera, turning slowly: the
// object's own SLAM must recover the camera's path w.r.t. the object and its shape up to
// a similarity.
TEST(ObjectReconstructionTest, ReconstructsAPassingRigidObject) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  std::vector<Eigen::Vector3d> points_obj;  // object frame: 4 x 1.5 x 1.5 m box, points on and in it
  for (int i = 0; i < 150; ++i) points_obj.emplace_back(4.0 * u(rng), 1.5 * u(rng), 1.5 * u(rng));
  const double focal = 525.0;
  ObjectReconstructionOptions options;
  SlamOptions slam;
  slam.ba.time_limited = false;  // a loaded machine must not cut the BA short
  slam.background_ba = false;
  ObjectReconstruction rec(options, slam);
  std::vector<Eigen::Vector3d> est_c, true_c;
  std::vector<ObjectReconstructionResult> last;
  int64_t map_id = 0;
  // cam_from_obj in image k: the object at 10 m, moving right to left, turning 0.5 deg
  // per image; and its tracks in that image.
  auto cam_from_obj_at = [](int k) {
    const double yaw = 0.5 * M_PI / 180.0 * k;
    return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY())),
                   Eigen::Vector3d(3.0 - 0.1 * k, 0.5, 10.0));
  };
  auto tracks_at = [&](int k) {
    ObjectTracksInput in;
    in.id = 7;
    for (size_t i = 0; i < points_obj.size(); ++i) {
      const Eigen::Vector3d pc = cam_from_obj_at(k) * points_obj[i];
      in.track_ids.push_back(static_cast<int64_t>(i));
      in.xy.push_back(pc.head<2>() / pc.z());
    }
    return in;
  };
  for (int k = 0; k < 60; ++k) {
    const Rigid3d cam_from_obj = cam_from_obj_at(k);
    last = rec.Update(k, 1000000 + k * 33333, focal, {tracks_at(k)});
    ASSERT_EQ(last.size(), 1u);
    if (!last[0].valid) continue;
    if (map_id == 0) map_id = last[0].map_id;
    EXPECT_EQ(last[0].map_id, map_id) << "one map for a well-tracked object";
    est_c.push_back(last[0].cam_from_obj.Inverse().translation);
    true_c.push_back(cam_from_obj.Inverse().translation);
  }
  ASSERT_GE(est_c.size(), 30u) << "the object was reconstructed early";
  EXPECT_EQ(rec.maps_started(), 1);
  Eigen::Matrix3Xd src(3, est_c.size()), dst(3, true_c.size());
  for (size_t i = 0; i < est_c.size(); ++i) {
    src.col(static_cast<Eigen::Index>(i)) = est_c[i];
    dst.col(static_cast<Eigen::Index>(i)) = true_c[i];
  }
  const Eigen::Matrix4d T = Eigen::umeyama(src, dst, true);
  double err2 = 0.0, path = 0.0;
  for (size_t i = 0; i < est_c.size(); ++i) {
    const Eigen::Vector3d a = (T * est_c[i].homogeneous()).head<3>();
    err2 += (a - true_c[i]).squaredNorm();
    if (i > 0) path += (true_c[i] - true_c[i - 1]).norm();
  }
  const double rmse = std::sqrt(err2 / static_cast<double>(est_c.size()));
  EXPECT_LT(rmse / path, 0.02) << "camera-relative trajectory within 2 % of its path";
  // Shape: the last output's points against the truth through the same similarity.
  ObjectReconstructionResult with_points;
  for (int k = 60; k < 80 && !with_points.points_included; ++k) {
    with_points = rec.Update(k, 1000000 + k * 33333, focal, {tracks_at(k)})[0];
  }
  ASSERT_TRUE(with_points.points_included);
  ASSERT_GE(with_points.points.size(), 50u);
  // Each reconstructed point is near some true point (ids are not in the output).
  int near = 0;
  for (const Eigen::Vector3d& p : with_points.points) {
    const Eigen::Vector3d a = (T * p.homogeneous()).head<3>();
    double best = 1e9;
    for (const Eigen::Vector3d& q : points_obj) best = std::min(best, (a - q).norm());
    near += best < 0.08;  // 2 % of the 4 m size
  }
  EXPECT_GE(near, static_cast<int>(0.9 * with_points.points.size()));
}

TEST(ObjectReconstructionTest, ChoosesLargestObjectsAndForgetsGoneOnes) {
  ObjectReconstructionOptions options;
  options.max_objects = 1;
  options.min_tracks = 10;
  options.forget_after_frames = 3;
  ObjectReconstruction rec(options, SlamOptions());
  auto object = [](int id, int n) {
    ObjectTracksInput in;
    in.id = id;
    for (int i = 0; i < n; ++i) {
      in.track_ids.push_back(id * 1000 + i);
      in.xy.emplace_back(0.01 * i, 0.002 * id);
    }
    return in;
  };
  std::vector<ObjectReconstructionResult> r = rec.Update(0, 0, 500.0, {object(1, 12), object(2, 30), object(3, 5)});
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].id, 2) << "the object with most tracks";
  EXPECT_FALSE(r[0].valid);
  for (int k = 1; k <= 4; ++k) rec.Update(k, k, 500.0, {object(1, 12)});
  EXPECT_EQ(rec.num_reconstructions(), 1u);
  r = rec.Update(5, 5, 500.0, {object(1, 12)});
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].id, 1) << "object 2 gone for longer than forget_after_frames: object 1 takes its place";
  ObjectReconstructionOptions off = options;
  off.enabled = false;
  ObjectReconstruction none(off, SlamOptions());
  EXPECT_TRUE(none.Update(0, 0, 500.0, {object(2, 30)}).empty());
}

// Published object points leave out what lies far outside the body: on sim-crossing an
// object map held points 9 and 6000 units away from a body 0.16 units across, which the
// objects' point clouds carried into the world for planners.
TEST(ObjectReconstructionTest, PublishedPointsLeaveOutPointsFarOutsideTheBody) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 60; ++i) {
    points.emplace_back(5.0 + 0.1 * (i % 5), 0.1 * ((i / 5) % 4) - 0.15, 0.05 * (i / 20));
  }
  const std::vector<Eigen::Vector3d> body = points;
  points.emplace_back(14.0, 0.0, 0.0);
  points.emplace_back(6000.0, 10.0, -3.0);
  points.emplace_back(5.2, 2.5, 0.0);
  const std::vector<Eigen::Vector3d> kept = CompactPoints(points, 4.0);
  ASSERT_EQ(kept.size(), body.size());
  for (size_t i = 0; i < body.size(); ++i) EXPECT_EQ(kept[i], body[i]);  // the body, in order
  EXPECT_EQ(CompactPoints(points, 0.0).size(), points.size());  // 0: everything
  const std::vector<Eigen::Vector3d> few(points.end() - 5, points.end());
  EXPECT_EQ(CompactPoints(few, 4.0).size(), few.size());  // too few to tell the body
}

}  // namespace
}  // namespace mbslam

namespace mbslam {
namespace {

// Published points: those seen from min_point_keyframes keyframes, or from all of them
// while the map is younger.
TEST(ObjectReconstructionTest, MaturePointsNeedThreeKeyframesOnceThereAreThree) {
  Map map;
  std::vector<int64_t> kf;
  for (int k = 0; k < 2; ++k) kf.push_back(map.AddKeyframe(Keyframe()));
  auto add_point = [&](double x, int views) {
    MapPoint p;
    p.position = Eigen::Vector3d(x, 0.0, 0.0);
    const int64_t id = map.AddPoint(p);
    for (int v = 0; v < views; ++v) map.AddObservation(id, kf[static_cast<size_t>(v)], Eigen::Vector2d::Zero());
  };
  add_point(1.0, 2);
  add_point(2.0, 1);
  // Two keyframes: the points both saw.
  std::vector<Eigen::Vector3d> pts = MaturePoints(map, 3);
  ASSERT_EQ(pts.size(), 1u);
  EXPECT_EQ(pts[0].x(), 1.0);
  kf.push_back(map.AddKeyframe(Keyframe()));
  add_point(3.0, 3);
  // Three keyframes: only the point all three saw.
  pts = MaturePoints(map, 3);
  ASSERT_EQ(pts.size(), 1u);
  EXPECT_EQ(pts[0].x(), 3.0);
  EXPECT_EQ(MaturePoints(map, 1).size(), 3u);
  EXPECT_EQ(MaturePoints(map, 2).size(), 2u);
}

}  // namespace
}  // namespace mbslam
