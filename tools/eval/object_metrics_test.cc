#include "tools/eval/object_metrics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace mbslam {
namespace eval {
namespace {

// A camera driving along x looking along x (camera z = world x), a car crossing ahead.
struct Scene {
  Trajectory camera;
  std::map<int, BodyTruth> bodies;
};

Scene MakeScene() {
  Scene s;
  Eigen::Matrix3d world_from_cam_rot;
  world_from_cam_rot << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  BodyTruth car;
  car.id = 1;
  car.name = "car";
  car.extent = Eigen::Vector3d(4.2, 1.8, 1.5);
  BodyTruth person = car;
  person.id = 2;
  person.name = "person";
  for (int i = 0; i < 60; ++i) {
    const int64_t t = 1000000 + i * 33333;
    const double ts = i / 30.0;
    s.camera.push_back({t, Rigid3d(world_from_cam_rot, Eigen::Vector3d(ts, 0.0, 1.5))});
    car.poses.push_back(
        {t, Rigid3d(Eigen::Matrix3d::Identity(), Eigen::Vector3d(15.0, 8.0 - 5.0 * ts, 0.75))});
    person.poses.push_back(
        {t, Rigid3d(Eigen::Matrix3d::Identity(), Eigen::Vector3d(8.0, -3.0 + 1.0 * ts, 0.9))});
  }
  s.bodies[1] = car;
  s.bodies[2] = person;
  return s;
}

TEST(ObjectMetrics, ScaleAboutTheCameraAndDepth) {
  const Scene scene = MakeScene();
  // The estimate world is the truth scaled by 0.5 (monocular map units); object 7 is the
  // car with its own scale 20 % too large about the camera; object 9 is the person,
  // exact; object 11 is a ghost far from everything.
  Sim3d gt_from_est;
  gt_from_est.scale = 2.0;
  const Sim3d est_from_gt = gt_from_est.Inverse();
  std::map<int, ObjectEstimate> est;
  for (size_t i = 0; i < scene.camera.size(); ++i) {
    const Eigen::Vector3d c = scene.camera[i].pose.translation;
    const Eigen::Vector3d car = scene.bodies.at(1).poses[i].pose.translation;
    const Eigen::Vector3d person = scene.bodies.at(2).poses[i].pose.translation;
    ObjectSample a;
    a.utime = scene.camera[i].utime;
    a.position = est_from_gt * Eigen::Vector3d(c + 1.2 * (car - c));
    est[7].id = 7;
    est[7].samples.push_back(a);
    ObjectSample b;
    b.utime = a.utime;
    b.position = est_from_gt * person;
    b.depth = (person.x() - c.x()) / 2.0;  // in estimate units
    est[9].id = 9;
    est[9].samples.push_back(b);
    ObjectSample g;
    g.utime = a.utime;
    g.position = Eigen::Vector3d(500, 500, 0);
    est[11].id = 11;
    est[11].samples.push_back(g);
  }
  ObjectMetricsOptions options;
  options.max_match_distance = 10.0;  // the car estimate is 20 % of ~17 m off
  ObjectsEvaluation r;
  ASSERT_TRUE(EvaluateObjects(est, scene.bodies, scene.camera, gt_from_est, options, &r).ok());
  EXPECT_EQ(r.num_est_objects, 3);
  EXPECT_EQ(r.unmatched_est, 1);
  EXPECT_EQ(r.unmatched_phantoms, 1);  // the estimate at (500, 500, 0) is near no body
  EXPECT_EQ(r.unmatched_fragments, 0);
  EXPECT_EQ(r.unmatched_samples, static_cast<int>(est[11].samples.size()));
  EXPECT_EQ(r.est_samples, static_cast<int>(est[7].samples.size() + est[9].samples.size() +
                                            est[11].samples.size()));
  ASSERT_EQ(r.objects.size(), 2u);
  const ObjectResult& car = r.objects[0];
  EXPECT_EQ(car.est_id, 7);
  EXPECT_EQ(car.gt_id, 1);
  EXPECT_EQ(car.num_samples, 60);
  EXPECT_NEAR(car.best_scale, 1.0 / 1.2, 1e-9);
  EXPECT_NEAR(car.relative_scale_error, 1.0 - 1.0 / 1.2, 1e-9);
  EXPECT_LT(car.position_error_scaled.max, 1e-9);
  EXPECT_GT(car.position_error.min, 0.2 * 10.0);  // 20 % of >= 10 m
  // Depth error over time: 20 % of the true depth (x distance) at every sample.
  ASSERT_EQ(car.depth_error_over_time.size(), 60u);
  for (size_t i = 0; i < 60; ++i) {
    const double true_depth = 15.0 - i / 30.0;
    EXPECT_NEAR(car.depth_error_over_time[i].second, 0.2 * true_depth, 1e-9);
  }
  const ObjectResult& person = r.objects[1];
  EXPECT_EQ(person.gt_id, 2);
  EXPECT_LT(person.position_error.max, 1e-9);
  EXPECT_LT(person.depth_error.max, 1e-9);  // the given depth (scaled by 2) is right
  EXPECT_NEAR(person.best_scale, 1.0, 1e-9);
}

TEST(ObjectMetrics, PredictedVolumeHitRate) {
  const Scene scene = MakeScene();
  std::map<int, ObjectEstimate> est;
  const BodyTruth& car = scene.bodies.at(1);
  est[3].id = 3;
  // One estimate per frame for the first 30 frames, each with a 1 s prediction: every
  // other prediction is centred on the truth, the rest 3 m off (box half size 1 m).
  for (int i = 0; i < 30; ++i) {
    ObjectSample s;
    s.utime = car.poses[static_cast<size_t>(i)].utime;
    s.position = car.poses[static_cast<size_t>(i)].pose.translation;
    PredictedVolume v;
    v.horizon_us = 999990;  // within the tolerance of 1 s
    v.utime = s.utime + v.horizon_us;
    Rigid3d future;
    ASSERT_TRUE(InterpolatePose(car.poses, v.utime, 100000, &future));
    v.center =
        future.translation + (i % 2 ? Eigen::Vector3d(0.0, 3.0, 0.0) : Eigen::Vector3d::Zero());
    v.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
    v.half_extent = Eigen::Vector3d::Ones();
    s.volumes.push_back(v);
    PredictedVolume other = v;  // another horizon: not counted
    other.horizon_us = 500000;
    s.volumes.push_back(other);
    est[3].samples.push_back(s);
  }
  ObjectsEvaluation r;
  ASSERT_TRUE(
      EvaluateObjects(est, scene.bodies, scene.camera, Sim3d(), ObjectMetricsOptions(), &r).ok());
  ASSERT_EQ(r.objects.size(), 1u);
  EXPECT_EQ(r.objects[0].volumes_checked, 30);
  EXPECT_EQ(r.objects[0].volumes_hit, 15);
  EXPECT_DOUBLE_EQ(r.hit_rate, 0.5);
  // Size of the predictions against the true box: 2 x 2 x 2 m over 4.2 x 1.8 x 1.5 m.
  EXPECT_NEAR(r.objects[0].volume_ratio_median, 8.0 / (4.2 * 1.8 * 1.5), 1e-9);
  EXPECT_NEAR(r.volume_ratio_median, 8.0 / (4.2 * 1.8 * 1.5), 1e-9);
  // With only the matched estimate, every estimate's volumes are its volumes.
  EXPECT_EQ(r.volumes_checked_all, 30);
  EXPECT_EQ(r.volumes_hit_all, 15);
  // A second estimate of the car (a fragment) whose volumes all hold the truth counts
  // in the all-estimates rate only.
  est[4] = est[3];
  est[4].id = 4;
  for (ObjectSample& s : est[4].samples) {
    s.position += Eigen::Vector3d(0.0, 0.5, 0.0);
    Rigid3d future;
    ASSERT_TRUE(InterpolatePose(car.poses, s.volumes[0].utime, 100000, &future));
    s.volumes[0].center = future.translation;
  }
  ASSERT_TRUE(
      EvaluateObjects(est, scene.bodies, scene.camera, Sim3d(), ObjectMetricsOptions(), &r).ok());
  EXPECT_EQ(r.unmatched_fragments, 1);
  EXPECT_EQ(r.volumes_checked, 30);
  EXPECT_EQ(r.volumes_checked_all, 60);
  EXPECT_EQ(r.volumes_hit_all, 45);
  EXPECT_DOUBLE_EQ(r.hit_rate_all, 0.75);
  // The volumes 3 m off the car's centre sideways (box half size 1 m, turned 0.3 rad: at
  // most 1.3 m across) do not reach its 1.8 m wide box either; the others overlap it.
  EXPECT_EQ(r.volumes_overlapping_all, 45);
}

TEST(PredictedVolume, OrientedContainment) {
  PredictedVolume v;
  v.center = Eigen::Vector3d(1, 1, 0);
  v.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitZ()));
  v.half_extent = Eigen::Vector3d(2.0, 0.5, 1.0);
  EXPECT_TRUE(v.Contains(Eigen::Vector3d(1, 1, 0)));
  EXPECT_TRUE(v.Contains(Eigen::Vector3d(2.2, 2.2, 0.5)));    // along the box's long axis
  EXPECT_FALSE(v.Contains(Eigen::Vector3d(2.2, -0.2, 0.0)));  // across it
  EXPECT_FALSE(v.Contains(Eigen::Vector3d(1, 1, 1.5)));
}

TEST(ObjectMetrics, UnmatchedEstimatesAreFragmentsOrPhantoms) {
  const Scene scene = MakeScene();
  const Sim3d gt_from_est;  // identity
  std::map<int, ObjectEstimate> est;
  for (size_t i = 0; i < scene.camera.size(); ++i) {
    const Eigen::Vector3d person = scene.bodies.at(2).poses[i].pose.translation;
    ObjectSample a;
    a.utime = scene.camera[i].utime;
    a.position = person;
    est[1].samples.push_back(a);
    a.position = person + Eigen::Vector3d(0.0, 0.3, 0.0);  // a second estimate of the person
    est[2].samples.push_back(a);
    if (i % 2 == 0) {
      a.position = Eigen::Vector3d(-40.0, 40.0, 0.0);  // near nothing
      est[3].samples.push_back(a);
    }
  }
  for (auto& [id, e] : est) e.id = id;
  ObjectsEvaluation r;
  ASSERT_TRUE(EvaluateObjects(est, scene.bodies, scene.camera, gt_from_est, ObjectMetricsOptions(), &r).ok());
  ASSERT_EQ(r.objects.size(), 1u);
  EXPECT_EQ(r.objects[0].est_id, 1);
  EXPECT_EQ(r.unmatched_est, 2);
  EXPECT_EQ(r.unmatched_fragments, 1);
  EXPECT_EQ(r.unmatched_phantoms, 1);
  EXPECT_EQ(r.est_samples, static_cast<int>(est[1].samples.size() + est[2].samples.size() + est[3].samples.size()));
  EXPECT_EQ(r.unmatched_samples, static_cast<int>(est[2].samples.size() + est[3].samples.size()));
  EXPECT_EQ(r.fragment_samples, static_cast<int>(est[2].samples.size()));
  EXPECT_EQ(r.phantom_samples, static_cast<int>(est[3].samples.size()));
  EXPECT_EQ(r.unmatched_short, 0);
  // One sample near nothing is too short to call a phantom.
  est[4].id = 4;
  est[4].samples.push_back(est[3].samples.front());
  ASSERT_TRUE(EvaluateObjects(est, scene.bodies, scene.camera, gt_from_est, ObjectMetricsOptions(), &r).ok());
  EXPECT_EQ(r.unmatched_short, 1);
  EXPECT_EQ(r.unmatched_phantoms, 1);
}


TEST(ObjectMetrics, OrientedBoxOverlap) {
  PredictedVolume v;
  v.center = Eigen::Vector3d::Zero();
  v.half_extent = Eigen::Vector3d(1.0, 1.0, 1.0);
  const Eigen::Quaterniond I = Eigen::Quaterniond::Identity();
  const Eigen::Vector3d h(0.5, 0.5, 0.5);
  EXPECT_TRUE(v.Overlaps(Eigen::Vector3d(1.4, 0.0, 0.0), I, h));   // faces 0.1 apart inward
  EXPECT_FALSE(v.Overlaps(Eigen::Vector3d(1.6, 0.0, 0.0), I, h));  // 0.1 apart
  EXPECT_FALSE(v.Overlaps(Eigen::Vector3d(0.0, 0.0, -1.6), I, h));
  // Turned 45 deg about z, the small box reaches 0.5 * sqrt(2) = 0.707 along x.
  const Eigen::Quaterniond r(Eigen::AngleAxisd(M_PI / 4.0, Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE(v.Overlaps(Eigen::Vector3d(1.65, 0.0, 0.0), r, h));
  EXPECT_FALSE(v.Overlaps(Eigen::Vector3d(1.75, 0.0, 0.0), r, h));
  // Corner to corner along the diagonal: apart only along an edge-cross axis or a face.
  EXPECT_FALSE(v.Overlaps(Eigen::Vector3d(1.6, 1.6, 1.6), I, h));
  EXPECT_TRUE(v.Overlaps(Eigen::Vector3d(1.4, 1.4, 1.4), I, h));
  // Symmetric.
  PredictedVolume w;
  w.center = Eigen::Vector3d(1.65, 0.0, 0.0);
  w.orientation = r;
  w.half_extent = h;
  EXPECT_TRUE(w.Overlaps(Eigen::Vector3d::Zero(), I, v.half_extent));
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
