#include "tools/sim/pose_track.h"

#include <gtest/gtest.h>

#include <cmath>

namespace mbslam {
namespace sim {
namespace {

TEST(PlanarPath, StraightConstantSpeed) {
  PlanarPath path(1.0, 2.0, M_PI / 2, 1.5);
  path.Drive(4.0);
  const auto s = path.At(2.0);
  EXPECT_NEAR(s.x, 1.0, 1e-9);
  EXPECT_NEAR(s.y, 2.0 + 3.0, 1e-9);
  EXPECT_NEAR(s.speed, 1.5, 1e-12);
  // Extrapolation before the start and after the end keeps the motion.
  EXPECT_NEAR(path.At(-1.0).y, 0.5, 1e-9);
  EXPECT_NEAR(path.At(6.0).y, 2.0 + 9.0, 1e-9);
}

TEST(PlanarPath, TurnFollowsCircularArc) {
  const double v = 2.0, w = 0.5;  // radius 4 m
  PlanarPath path(0.0, 0.0, 0.0, v);
  path.Drive(M_PI / w, 0.0, w);  // half a circle
  const auto s = path.At(M_PI / w);
  EXPECT_NEAR(s.x, 0.0, 1e-6);
  EXPECT_NEAR(s.y, 2.0 * v / w, 1e-6);
  EXPECT_NEAR(s.yaw, M_PI, 1e-9);
  // After the end, the arc continues analytically (a full circle returns to the start).
  const auto back = path.At(2.0 * M_PI / w);
  EXPECT_NEAR(back.x, 0.0, 1e-6);
  EXPECT_NEAR(back.y, 0.0, 1e-6);
}

TEST(PlanarPath, StartFromRest) {
  PlanarPath path(0.0, 0.0, 0.0, 0.0);
  path.Wait(2.0).RampTo(2.0, 1.0).Drive(1.0);
  EXPECT_DOUBLE_EQ(path.At(-5.0).x, 0.0);  // at rest forever before the start
  EXPECT_DOUBLE_EQ(path.At(1.9).x, 0.0);
  EXPECT_NEAR(path.At(3.0).x, 1.0, 1e-9);  // 0.5 * a * t^2 with a = 2
  EXPECT_NEAR(path.At(4.0).x, 3.0, 1e-9);
  EXPECT_NEAR(path.At(4.0).speed, 2.0, 1e-9);
}

TEST(PoseTrack, InterpolatesAndDifferentiates) {
  // A body spinning at 0.3 rad/s about z while moving along x at 2 m/s.
  const auto fn = [](int64_t utime) {
    const double t = 1e-6 * static_cast<double>(utime);
    return PlanarPose(2.0 * t, 0.0, 1.0, 0.3 * t);
  };
  const PoseTrack track = PoseTrack::Sample(fn, 0, 5000000, 1000);
  const int64_t t = 2345678;  // between samples
  const Rigid3d expected = fn(t);
  const Rigid3d got = track.WorldFromBody(t);
  // Geodesic (screw) interpolation between 1 ms samples: ~v w dt^2 / 8 off a straight line.
  EXPECT_LT(TranslationDistance(expected, got), 1e-6);
  EXPECT_LT(RotationDistance(expected, got), 1e-9);
  const MotionState s = track.StateAt(t);
  EXPECT_NEAR(s.linear_velocity.x(), 2.0, 1e-6);
  EXPECT_NEAR(s.linear_velocity.y(), 0.0, 1e-6);
  EXPECT_NEAR(s.angular_velocity.z(), 0.3, 1e-6);
  EXPECT_NEAR(s.angular_velocity.head<2>().norm(), 0.0, 1e-9);
}

TEST(ForwardCameraMount, AxesLookAlongBaseX) {
  const Rigid3d base_from_cam = ForwardCameraMount(Eigen::Vector3d(0.1, 0.0, 0.5), 0.0);
  const Eigen::Matrix3d R = base_from_cam.RotationMatrix();
  EXPECT_LT((R * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitX()).norm(),
            1e-12);  // optical axis forward
  EXPECT_LT((R * Eigen::Vector3d::UnitX() + Eigen::Vector3d::UnitY()).norm(),
            1e-12);  // image right = base right
  EXPECT_LT((R * Eigen::Vector3d::UnitY() + Eigen::Vector3d::UnitZ()).norm(),
            1e-12);  // image down = base down
  const Rigid3d pitched = ForwardCameraMount(Eigen::Vector3d::Zero(), 0.2);
  EXPECT_NEAR((pitched.rotation * Eigen::Vector3d::UnitZ()).z(), -std::sin(0.2),
              1e-12);  // looks down
}

TEST(SmoothNoise3, HasRequestedRmsAndIsDeterministic) {
  const SmoothNoise3 a(5, 0.01, 0.5, 3.0), b(5, 0.01, 0.5, 3.0), c(6, 0.01, 0.5, 3.0);
  double sum_sq = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double t = 0.01 * i;
    const Eigen::Vector3d v = a.At(t);
    sum_sq += v.x() * v.x();
    EXPECT_EQ(v, b.At(t));
  }
  EXPECT_NEAR(std::sqrt(sum_sq / n), 0.01, 0.002);
  EXPECT_NE(a.At(1.0), c.At(1.0));
}

}  // namespace
}  // namespace sim
}  // namespace mbslam
