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

namespace mbslam {
namespace {

// A wide envelope (odometry that misses the pitch): the static point moved by one of the
// envelope's motions lies off the mean motion's prediction. Averaged over the envelope it
// looks moving; with "max" it is static because a motion in the envelope explains it.
TEST(StaticLikelihood, EnvelopeMaxKeepsPointsExplainedByAPlausibleMotion) {
  RelativeMotion m = Forward();
  const Eigen::Vector3d p(1.0, 0.5, 8.0);
  m.covariance = Matrix6d::Zero();
  m.covariance.topLeftCorner<3, 3>() = 1e-6 * Eigen::Matrix3d::Identity();
  m.covariance(3, 3) = 0.004 * 0.004;  // pitch (rotation about x)
  m.covariance(4, 4) = m.covariance(5, 5) = 1e-8;
  // The truth: the envelope's motion with the largest pitch.
  const std::vector<MotionSample> samples = MotionSigmaPoints(m);
  const MotionSample* edge = &samples[0];
  for (const MotionSample& s : samples) {
    if (Eigen::AngleAxisd(s.R * m.cam_n_from_cam_r.RotationMatrix().transpose()).angle() >
        Eigen::AngleAxisd(edge->R * m.cam_n_from_cam_r.RotationMatrix().transpose()).angle()) {
      edge = &s;
    }
  }
  const Rigid3d truth(edge->R, edge->t);
  StaticLikelihoodOptions o;
  auto eval = [&](const std::string& combine) {
    o.envelope_combine = combine;
    return ComputeStaticLikelihood(p.hnormalized(), (truth * p).hnormalized(), samples, true, true,
                                   DepthBound{1.0, 50.0}, kFocal, o);
  };
  const StaticLikelihood mean = eval("mean");
  const StaticLikelihood max = eval("max");
  EXPECT_GT(mean.epipolar_px, 2.0) << "the mean motion does not explain the point";
  EXPECT_LT(mean.p_static, 0.5);
  EXPECT_GT(max.p_static, 0.8);
  // "max_odometry" is decided by the segmenter from the motion's source; here it is "mean".
  EXPECT_DOUBLE_EQ(eval("max_odometry").p_static, mean.p_static);
  o.envelope_combine = "median";
  EXPECT_FALSE(o.Check());
}

}  // namespace
}  // namespace mbslam
