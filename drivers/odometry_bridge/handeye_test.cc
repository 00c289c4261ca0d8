#include "drivers/odometry_bridge/handeye.h"

#include <gtest/gtest.h>

#include <random>

#include "common/util/time.h"

namespace mbslam {
namespace {

const Rigid3d kTrueBaseFromCam(
    Eigen::Quaterniond(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ()) *
                       Eigen::AngleAxisd(-M_PI / 2 - 0.1, Eigen::Vector3d::UnitX())),
    Eigen::Vector3d(0.25, -0.08, 0.6));

// Odometry (odom_from_base at 20 Hz) and camera (world_from_cam at 10 Hz, between
// odometry samples) of the same motion. The camera's world is an arbitrary frame and
// its translations are in units of `scale` metres (a monocular map).
struct Trajectories {
  std::vector<TimedPose> odom_from_base;
  std::vector<TimedPose> world_from_cam;
};

Trajectories Make(bool planar, double scale, double noise, int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const Rigid3d world_from_odom(Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized())),
                                Eigen::Vector3d(3, 1, -2));
  Trajectories t;
  Rigid3d base;
  for (int i = 0; i < n; ++i) {
    const int64_t utime = 1000000 + 100000 * int64_t{i};
    // Drive and turn with varying speed and turn rate; the general case also pitches
    // and rolls.
    Vector6d xi;
    const double turn = 0.3 * std::sin(0.37 * i) + 0.05;
    if (planar) {
      xi << 0.08 + 0.03 * std::cos(0.2 * i), 0.0, 0.0, 0.0, 0.0, turn;
    } else {
      xi << 0.08, 0.02 * std::sin(0.5 * i), 0.01, 0.15 * std::sin(0.23 * i), 0.12 * std::cos(0.31 * i), turn;
    }
    const Rigid3d next = base * Rigid3d::Exp(xi);
    const Rigid3d mid = Rigid3d::Interpolate(base, next, 0.5);
    t.odom_from_base.push_back(TimedPose{utime, base});
    t.odom_from_base.push_back(TimedPose{utime + 50000, mid});
    Rigid3d cam = world_from_odom * mid * kTrueBaseFromCam;
    cam.translation /= scale;
    if (noise > 0) {
      Vector6d e;
      for (int k = 0; k < 6; ++k) e[k] = noise * gauss(rng);
      cam = Rigid3d::Exp(e) * cam;
    }
    t.world_from_cam.push_back(TimedPose{utime + 50000, cam});
    base = next;
  }
  return t;
}

std::vector<MotionPair> Pairs(const Trajectories& t, double min_rotation_deg = 5.0) {
  PairingOptions options;
  options.min_rotation_deg = min_rotation_deg;
  std::vector<MotionPair> pairs;
  int outside = 0;
  EXPECT_TRUE(BuildMotionPairs(t.world_from_cam, t.odom_from_base, options, &pairs, &outside).ok());
  EXPECT_EQ(outside, 0);
  return pairs;
}

TEST(HandEye, GeneralMotionRecoversRotationTranslationAndScale) {
  const Trajectories t = Make(false, 2.5, 0.0, 120, 1);
  const std::vector<MotionPair> pairs = Pairs(t);
  ASSERT_GT(pairs.size(), 10u);
  HandEyeResult r;
  ASSERT_TRUE(SolveHandEye(pairs, HandEyeOptions(), &r).ok());
  EXPECT_FALSE(r.planar);
  EXPECT_LT(RotationDistance(r.base_from_cam, kTrueBaseFromCam), 1e-9);
  EXPECT_LT(TranslationDistance(r.base_from_cam, kTrueBaseFromCam), 1e-9);
  EXPECT_NEAR(r.scale, 2.5, 1e-9);
  EXPECT_LT(r.rotation_rms_rad, 1e-9);
  EXPECT_LT(r.translation_rms_m, 1e-9);
  EXPECT_NE(r.observability.find("general"), std::string::npos);
}

TEST(HandEye, MetricCameraFixesTheScale) {
  const Trajectories t = Make(false, 1.0, 0.0, 80, 2);
  HandEyeOptions options;
  options.metric_camera = true;
  HandEyeResult r;
  ASSERT_TRUE(SolveHandEye(Pairs(t), options, &r).ok());
  EXPECT_EQ(r.scale, 1.0);
  EXPECT_LT(TranslationDistance(r.base_from_cam, kTrueBaseFromCam), 1e-9);
}

TEST(HandEye, PlanarMotionLeavesOnlyTheHeightUnobservable) {
  const Trajectories t = Make(true, 0.4, 0.0, 150, 3);
  HandEyeOptions options;
  options.prior_offset_along_axis_m = 0.55;  // true: 0.6
  HandEyeResult r;
  ASSERT_TRUE(SolveHandEye(Pairs(t), options, &r).ok());
  EXPECT_TRUE(r.planar);
  EXPECT_LT(RotationDistance(r.base_from_cam, kTrueBaseFromCam), 1e-9);
  EXPECT_NEAR(r.base_from_cam.translation.x(), 0.25, 1e-9);
  EXPECT_NEAR(r.base_from_cam.translation.y(), -0.08, 1e-9);
  EXPECT_NEAR(r.base_from_cam.translation.z(), 0.55, 1e-12);  // the prior, not the data
  EXPECT_NEAR(r.scale, 0.4, 1e-9);
  EXPECT_LT(r.translation_rms_m, 1e-9);  // the height does not enter the residuals
  EXPECT_NE(r.observability.find("not"), std::string::npos);
  EXPECT_LT(std::abs(std::abs(r.axis_in_base.z()) - 1.0), 1e-9);
  // Forcing the general solver on planar data is refused, not answered wrongly.
  options.mode = "general";
  EXPECT_FALSE(SolveHandEye(Pairs(t), options, &r).ok());
}

TEST(HandEye, NoisyDataGivesAnApproximateAnswerAndResiduals) {
  for (bool planar : {false, true}) {
    const Trajectories t = Make(planar, 1.7, 2e-4, 300, 4);
    HandEyeOptions options;
    options.prior_offset_along_axis_m = 0.6;
    HandEyeResult r;
    ASSERT_TRUE(SolveHandEye(Pairs(t), options, &r).ok());
    EXPECT_EQ(r.planar, planar);
    EXPECT_LT(RotationDistance(r.base_from_cam, kTrueBaseFromCam), 0.01) << planar;
    EXPECT_LT(TranslationDistance(r.base_from_cam, kTrueBaseFromCam), 0.03) << planar;
    EXPECT_NEAR(r.scale, 1.7, 0.05) << planar;
    EXPECT_GT(r.rotation_rms_rad, 0.0);
    EXPECT_EQ(r.rotation_residuals_rad.size(), static_cast<size_t>(r.pairs));
  }
}

TEST(HandEye, DegenerateMotionsAreRefused) {
  // Straight driving only: no rotation at all.
  std::vector<MotionPair> straight;
  for (int i = 0; i < 5; ++i) {
    MotionPair p;
    p.base_motion = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.5, 0, 0));
    p.cam_motion = kTrueBaseFromCam.Inverse() * p.base_motion * kTrueBaseFromCam;
    straight.push_back(p);
  }
  HandEyeResult r;
  const Status st = SolveHandEye(straight, HandEyeOptions(), &r);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("turn"), std::string::npos) << st.message();
  // Turning on the spot only (planar): scale and heading across the axis undetermined.
  std::vector<MotionPair> spin;
  for (int i = 1; i <= 5; ++i) {
    MotionPair p;
    p.base_motion = Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.2 * i, Eigen::Vector3d::UnitZ())),
                            Eigen::Vector3d::Zero());
    p.cam_motion = kTrueBaseFromCam.Inverse() * p.base_motion * kTrueBaseFromCam;
    spin.push_back(p);
  }
  EXPECT_FALSE(SolveHandEye(spin, HandEyeOptions(), &r).ok());
  EXPECT_FALSE(SolveHandEye({}, HandEyeOptions(), &r).ok());
}

TEST(HandEye, PairingCountsCameraPosesOutsideTheOdometry) {
  Trajectories t = Make(true, 1.0, 0.0, 40, 5);
  t.world_from_cam.insert(t.world_from_cam.begin(), TimedPose{10, Rigid3d()});  // before odometry
  PairingOptions options;
  std::vector<MotionPair> pairs;
  int outside = 0;
  ASSERT_TRUE(BuildMotionPairs(t.world_from_cam, t.odom_from_base, options, &pairs, &outside).ok());
  EXPECT_EQ(outside, 1);
  EXPECT_FALSE(pairs.empty());
  for (const MotionPair& p : pairs) {
    const bool turned = LogSO3(p.base_motion.RotationMatrix()).norm() >= options.min_rotation_deg * M_PI / 180;
    EXPECT_TRUE(turned || p.base_motion.translation.norm() >= options.min_translation_m);
  }
}

}  // namespace
}  // namespace mbslam
