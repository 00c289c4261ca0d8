#include "services/perception/segmentation/static_likelihood.h"

#include <gtest/gtest.h>

namespace mbslam {
namespace {

constexpr double kFocal = 500.0;

// Camera moving forward 0.5 m with a slight yaw.
RelativeMotion Forward() {
  RelativeMotion m;
  // x_n = R x_r + t: the camera moves +z, so static points move -z in its frame.
  m.cam_n_from_cam_r = Rigid3d(Eigen::Matrix3d(Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY())),
                               Eigen::Vector3d(0.0, 0.0, -0.5));
  m.covariance = Matrix6d::Identity() * 1e-6;
  m.scale_known = true;
  return m;
}

StaticLikelihood Eval(const RelativeMotion& m, const Eigen::Vector3d& p_r, const Eigen::Vector3d& p_n,
                      const DepthBound& bound, bool fvb) {
  StaticLikelihoodOptions o;
  o.use_fvb = fvb;
  return ComputeStaticLikelihood(p_r.hnormalized(), p_n.hnormalized(), MotionSigmaPoints(m), true,
                                 m.scale_known, bound, kFocal, o);
}

TEST(StaticLikelihood, StaticPointIsStatic) {
  const RelativeMotion m = Forward();
  const Eigen::Vector3d p(1.0, 0.5, 8.0);
  const StaticLikelihood l = Eval(m, p, m.cam_n_from_cam_r * p, DepthBound{1.0, 50.0}, true);
  EXPECT_GT(l.p_static, 0.85);
  EXPECT_LT(l.epipolar_px, 0.01);
  EXPECT_NEAR(l.p_fvb, 1.0, 1e-6);
}

TEST(StaticLikelihood, OffEpipolarMotionIsMoving) {
  const RelativeMotion m = Forward();
  const Eigen::Vector3d p(1.0, 0.5, 8.0);
  const Eigen::Vector3d moved = m.cam_n_from_cam_r * (p + Eigen::Vector3d(0.0, 0.08, 0.0));
  const StaticLikelihood l = Eval(m, p, moved, DepthBound(), true);
  EXPECT_GT(l.epipolar_px, 4.0);
  EXPECT_LT(l.p_static, 0.05);
}

// Thesis fig. 3.1 right / sec. 3.5.2: a point moving with the camera stays on its
// epipolar line; only the Flow Vector Bound catches it.
TEST(StaticLikelihood, DegenerateMotionCaughtOnlyByFvb) {
  const RelativeMotion m = Forward();
  const Eigen::Vector3d p(1.0, 0.5, 8.0);
  // The object moves forward with the camera (0.5 m): its image flow is ~pure rotation,
  const Eigen::Vector3d moved = m.cam_n_from_cam_r * (p + Eigen::Vector3d(0.0, 0.0, 0.5));
  // as if it were infinitely far, but the map says nothing here is beyond 10 m.
  const StaticLikelihood with = Eval(m, p, moved, DepthBound{2.0, 10.0}, true);
  const StaticLikelihood without = Eval(m, p, moved, DepthBound{2.0, 10.0}, false);
  EXPECT_LT(with.epipolar_px, 0.5);
  EXPECT_GT(without.p_static, 0.8);
  EXPECT_LT(with.p_static, 0.2);
  // Moving toward the epipole (faster than the camera) fails even without a map.
  const Eigen::Vector3d faster = m.cam_n_from_cam_r * (p + Eigen::Vector3d(0.0, 0.0, 1.2));
  EXPECT_LT(Eval(m, p, faster, DepthBound(), true).p_static, 0.3);
}

TEST(StaticLikelihood, KnownDepthGivesTightBound) {
  const RelativeMotion m = Forward();
  const Eigen::Vector3d p(1.0, 0.5, 8.0);
  const Eigen::Vector3d slower = m.cam_n_from_cam_r * (p + Eigen::Vector3d(0.0, 0.0, 0.4));
  EXPECT_LT(Eval(m, p, slower, DepthBound{7.6, 8.4}, true).p_static, 0.2);
  // Without the known depth the same flow looks like a point far away.
  EXPECT_GT(Eval(m, p, slower, DepthBound(), true).p_static, 0.8);
  EXPECT_GT(Eval(m, p, m.cam_n_from_cam_r * p, DepthBound{7.6, 8.4}, true).p_static, 0.85);
}

TEST(StaticLikelihood, ButterworthShape) {
  EXPECT_DOUBLE_EQ(FlowBoundProbability(5.0, 1.0, 10.0, 1.0, 10.0), 1.0);
  EXPECT_NEAR(FlowBoundProbability(11.0, 1.0, 10.0, 1.0, 10.0), 0.5, 1e-12);
  EXPECT_LT(FlowBoundProbability(12.0, 1.0, 10.0, 1.0, 10.0), 1e-5);
  EXPECT_GT(FlowBoundProbability(10.8, 1.0, 10.0, 1.0, 10.0), 0.98);
}

}  // namespace
}  // namespace mbslam
