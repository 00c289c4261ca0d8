#include "services/perception/slam/pose_estimator.h"
#include "services/perception/segmentation/relative_motion.h"
#include "services/perception/slam/slam_system.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

namespace mbslam {
namespace {

TEST(PoseEstimator, EpnpRansacWithOutliersAndRefinement) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2.0, 2.0), z(3.0, 10.0);
  std::normal_distribution<double> noise(0.0, 0.5 / 500.0);
  Vector6d xi;
  xi << 0.2, -0.1, 0.3, 0.05, -0.02, 0.1;
  const Rigid3d truth = Rigid3d::Exp(xi);
  std::vector<Eigen::Vector3d> X;
  std::vector<Eigen::Vector2d> xy;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d pc(u(rng), u(rng), z(rng));
    X.push_back(truth.Inverse() * pc);
    xy.push_back(pc.hnormalized() + Eigen::Vector2d(noise(rng), noise(rng)));
  }
  for (int i = 0; i < 40; ++i) xy[static_cast<size_t>(i)] += Eigen::Vector2d(0.05, -0.03);  // outliers
  const PoseEstimate est = EstimatePose(X, xy, 500.0, std::nullopt, PoseEstimatorOptions());
  ASSERT_TRUE(est.ok);
  EXPECT_TRUE(est.used_ransac);
  EXPECT_LT(TranslationDistance(est.cam_from_world, truth), 0.02);
  EXPECT_LT(RotationDistance(est.cam_from_world, truth), 2e-3);
  EXPECT_GE(est.num_inliers, 155);
  EXPECT_LE(est.num_inliers, 160);
  EXPECT_LT(est.rms_px, 1.0);
  // The covariance is positive definite and small.
  EXPECT_GT(est.covariance.determinant(), 0.0);
  EXPECT_LT(est.covariance.trace(), 1e-3);
  // A good prior skips RANSAC.
  const PoseEstimate again = EstimatePose(X, xy, 500.0, truth, PoseEstimatorOptions());
  EXPECT_FALSE(again.used_ransac);
  EXPECT_LT(TranslationDistance(again.cam_from_world, truth), 0.02);
}

// A small object far ahead: a turn about the vertical and a sideways translation explain
// its few degrees of view almost alike. Started from a pose turned by 0.1 rad and moved
// sideways to compensate, the refinement alone leaves much of the turn; the rotation
// prior (the true rotation, 0.5 deg) brings it back, and the covariance of the rotation
// stays within the prior's.
TEST(PoseEstimator, RotationPriorResolvesTheNarrowViewAmbiguity) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.25, 0.25), z(-0.2, 0.2);
  std::normal_distribution<double> noise(0.0, 0.5 / 500.0);
  const Rigid3d truth(Eigen::Matrix3d(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY())), Eigen::Vector3d(0.1, 0.0, 8.0));
  std::vector<Eigen::Vector3d> X;
  std::vector<Eigen::Vector2d> xy;
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector3d p(u(rng), 4.0 * u(rng), z(rng));  // object frame, a person-sized box
    X.push_back(p);
    xy.push_back((truth * p).hnormalized() + Eigen::Vector2d(noise(rng), noise(rng)));
  }
  // Turned by 0.1 rad about the vertical; the object's centre (its origin) still projects
  // where it did.
  const Rigid3d start(Eigen::Matrix3d(Eigen::AngleAxisd(0.15, Eigen::Vector3d::UnitY())), truth.translation);
  const std::vector<uint8_t> all(X.size(), 1);
  const Rigid3d free = RefinePose(start, X, xy, all, 500.0, 1.5, 10, nullptr);
  PoseRotationPrior prior;
  prior.cam_from_world = truth.rotation;
  prior.sigma_rad = 0.5 * M_PI / 180.0;
  Matrix6d info;
  const Rigid3d held = RefinePose(start, X, xy, all, 500.0, 1.5, 10, &info, &prior, 1.0);
  EXPECT_GT(RotationDistance(free, truth), 0.02);
  EXPECT_LT(RotationDistance(held, truth), 0.005);
  EXPECT_LT(RotationDistance(held, truth), 0.25 * RotationDistance(free, truth));
  // Covariance: sigma^2 (info)^-1 in normalised units; its rotation block within the prior's.
  const double s = 1.0 / 500.0;
  const Matrix6d cov = s * s * Matrix6d(info.inverse());
  EXPECT_LE(cov(4, 4), prior.sigma_rad * prior.sigma_rad * 1.0001);
  // Through EstimatePose too.
  const PoseEstimate est = EstimatePose(X, xy, 500.0, start, PoseEstimatorOptions(), prior);
  ASSERT_TRUE(est.ok);
  EXPECT_LT(RotationDistance(est.cam_from_world, truth), 0.005);
}

// A camera moving forward and a little sideways that sees 100 points shared with a
// posed reference image, only `num_3d` of them as map points: the epipolar-assisted
// resection takes the rotation and the direction of motion from the links, the length
// from the map points (without any, from the expected length), and refuses outliers
// among both.
constexpr double kDeg = M_PI / 180.0;

struct HybridScene {
  Rigid3d ref, truth;
  std::vector<Eigen::Vector3d> X;
  std::vector<Eigen::Vector2d> xy;
  EpipolarLinks links;
};

HybridScene MakeHybridScene(int num_3d, int num_link_outliers, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-2.0, 2.0), z(2.0, 8.0), angle(0.0, 2.0 * M_PI);
  std::normal_distribution<double> noise(0.0, 0.5 / 320.0);
  HybridScene s;
  s.ref = Rigid3d(Eigen::Matrix3d(Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1.0, 0.1).normalized())),
                  Eigen::Vector3d(0.5, -0.2, 1.0));
  // cam_n_from_cam_r: 1.1 deg of turn, 0.3 forward and 0.1 sideways.
  const Rigid3d rel(Eigen::Matrix3d(Eigen::AngleAxisd(0.02, Eigen::Vector3d(0.1, 1.0, 0.3).normalized())),
                    Eigen::Vector3d(-0.1, -0.02, -0.3));
  s.truth = rel * s.ref;
  s.links.references = {s.ref};
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d pc(u(rng), u(rng), z(rng));  // in the reference camera
    const Eigen::Vector3d pw = s.ref.Inverse() * pc;
    const Eigen::Vector2d x_cur = (s.truth * pw).hnormalized() + Eigen::Vector2d(noise(rng), noise(rng));
    s.links.reference.push_back(0);
    s.links.xy_ref.push_back(pc.hnormalized() + Eigen::Vector2d(noise(rng), noise(rng)));
    s.links.xy_cur.push_back(x_cur);
    if (i < num_3d) {
      s.X.push_back(pw);
      s.xy.push_back(x_cur);
    }
  }
  for (int i = 0; i < num_link_outliers; ++i) {
    const double a = angle(rng);
    s.links.xy_cur[static_cast<size_t>(99 - i)] += 0.05 * Eigen::Vector2d(std::cos(a), std::sin(a));  // 16 px
  }
  return s;
}

double DirectionErrorRad(const Rigid3d& a, const Rigid3d& b, const Rigid3d& ref) {
  const Eigen::Vector3d ta = (a * ref.Inverse()).translation, tb = (b * ref.Inverse()).translation;
  return std::acos(std::clamp(ta.normalized().dot(tb.normalized()), -1.0, 1.0));
}

// Against the two halves of its information (a resection on the map points alone, the
// 5-point essential matrix of the links alone), over 10 renderings: the combination is
// far more accurate than the resection, and unlike the two-view estimate has the length.
TEST(PoseEstimator, EpipolarAssistedPoseFromFewMapPoints) {
  double rot = 0.0, dir = 0.0, rot_5pt = 0.0, dir_5pt = 0.0, rot_pnp = 0.0, dir_pnp = 0.0;
  for (uint32_t seed = 1; seed <= 10; ++seed) {
    HybridScene s = MakeHybridScene(8, 15, seed);
    s.xy[0] += Eigen::Vector2d(0.05, 0.0);  // one map point off its track
    // The prediction: turned by 1 deg the wrong way and 40 % too short.
    const Rigid3d rel_truth = s.truth * s.ref.Inverse();
    const Rigid3d prior =
        Rigid3d(Eigen::Matrix3d(Eigen::AngleAxisd(0.017, Eigen::Vector3d::UnitX())), Eigen::Vector3d::Zero()) *
        Rigid3d(rel_truth.rotation, 0.6 * rel_truth.translation) * s.ref;
    const double expected = 0.6 * rel_truth.translation.norm();
    const HybridPoseEstimate h =
        EstimatePoseWithEpipolar(s.X, s.xy, s.links, prior, 0, 0, expected, 0.5, 320.0, PoseEstimatorOptions());
    ASSERT_TRUE(h.pose.ok) << seed;
    rot += RotationDistance(h.pose.cam_from_world, s.truth);
    dir += DirectionErrorRad(h.pose.cam_from_world, s.truth, s.ref);
    EXPECT_LT(RotationDistance(h.pose.cam_from_world, s.truth), 0.5 * kDeg) << seed;  // the prior is 1 deg off
    EXPECT_LT(DirectionErrorRad(h.pose.cam_from_world, s.truth, s.ref), 6.0 * kDeg) << seed;
    // The length comes from the map points, not from the (short) expectation.
    const double length = (h.pose.cam_from_world * s.ref.Inverse()).translation.norm();
    EXPECT_NEAR(length / rel_truth.translation.norm(), 1.0, 0.05) << seed;
    // The 85 true links are kept; an outlier moved along its epipolar line cannot be told.
    EXPECT_GE(h.num_link_inliers, 85) << seed;
    EXPECT_LE(h.num_link_inliers, 91) << seed;
    EXPECT_FALSE(h.pose.inliers[0]) << seed;
    EXPECT_EQ(h.pose.num_inliers, 7) << seed;
    EXPECT_GT(h.pose.covariance.determinant(), 0.0);

    RelativeMotion m;
    std::vector<uint8_t> inl;
    ASSERT_TRUE(EstimateRelativeMotion(s.links.xy_ref, s.links.xy_cur, 320.0, TwoViewOptions(), &m, &inl).ok());
    const Rigid3d five_point = Rigid3d(m.cam_n_from_cam_r.rotation, m.cam_n_from_cam_r.translation) * s.ref;
    rot_5pt += RotationDistance(five_point, s.truth);
    dir_5pt += DirectionErrorRad(five_point, s.truth, s.ref);
    const PoseEstimate pnp = EstimatePose(s.X, s.xy, 320.0, prior, PoseEstimatorOptions());
    rot_pnp += RotationDistance(pnp.cam_from_world, s.truth);
    dir_pnp += DirectionErrorRad(pnp.cam_from_world, s.truth, s.ref);
  }
  // Far better than the resection alone, and within fixed bounds: the two-view estimate
  // alone (which has no length) moves with its RANSAC's draws. Sums over the ten
  // renderings: this estimate rotation 0.022 rad, direction 0.28 rad; the resection 0.051
  // / 0.85; the two-view estimate 0.021 / 0.24 (MSAC), 0.018 / 0.20 (inlier count), 0.032
  // / 0.39 (cv::findEssentialMat).
  EXPECT_LT(rot, 0.8 * rot_pnp);
  EXPECT_LT(dir, 0.8 * dir_pnp);
  EXPECT_LT(rot, 0.03);
  EXPECT_LT(dir, 0.35);
  EXPECT_GT(rot_5pt, 0.0);  // the reference ran
  EXPECT_GT(dir_5pt, 0.0);
}

TEST(PoseEstimator, EpipolarAssistedPoseWithoutMapPointsTakesTheExpectedLength) {
  for (uint32_t seed = 1; seed <= 5; ++seed) {
    HybridScene s = MakeHybridScene(0, 10, seed);
    const Rigid3d rel_truth = s.truth * s.ref.Inverse();
    const double expected = 1.2 * rel_truth.translation.norm();
    const HybridPoseEstimate h =
        EstimatePoseWithEpipolar(s.X, s.xy, s.links, s.ref, 0, 0, expected, 0.5, 320.0, PoseEstimatorOptions());
    ASSERT_TRUE(h.pose.ok) << seed;
    EXPECT_EQ(h.pose.num_inliers, 0);
    EXPECT_LT(RotationDistance(h.pose.cam_from_world, s.truth), 0.5 * kDeg) << seed;
    EXPECT_LT(DirectionErrorRad(h.pose.cam_from_world, s.truth, s.ref), 6.0 * kDeg) << seed;
    EXPECT_NEAR((h.pose.cam_from_world * s.ref.Inverse()).translation.norm(), expected, 1e-3 * expected) << seed;
  }
}

// A camera 1.5 m above the ground (world z up, plane z = 0) moving 0.5 m forward, 0.2 m
// sideways and 0.05 m down while turning 3 deg; the reference sees `ground_points` ground
// points and 30 points of a wall 5 m ahead below its horizon (their rays meet the ground
// behind the wall), besides 20 points above the horizon.
struct GroundScene {
  EpipolarLinks links;
  Rigid3d ref, truth;
  int ground = 0, wall_below = 0;
};

GroundScene MakeGroundScene(uint32_t seed, double noise_px, int ground_points) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, noise_px / 320.0);
  // Camera axes in the world: x right = -y_w, y down = -z_w, z forward = x_w; pitched 15 deg down.
  Eigen::Matrix3d world_from_cam0;
  world_from_cam0 << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const Eigen::Matrix3d pitch =
      Eigen::AngleAxisd(-15.0 * kDeg, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Rigid3d world_from_ref(Eigen::Matrix3d(world_from_cam0 * pitch),
                               Eigen::Vector3d(0.0, 0.0, 1.5));
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(3.0 * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Rigid3d world_from_cur(Eigen::Matrix3d(turn * world_from_cam0 * pitch),
                               Eigen::Vector3d(0.5, 0.2, 1.45));
  GroundScene s;
  s.ref = world_from_ref.Inverse();
  s.truth = world_from_cur.Inverse();
  s.links.references.push_back(s.ref);
  const auto add = [&](const Eigen::Vector3d& X) {
    const Eigen::Vector3d pr = s.ref * X, pc = s.truth * X;
    if (pr.z() <= 0.1 || pc.z() <= 0.1) return false;
    const Eigen::Vector2d a = pr.hnormalized(), b = pc.hnormalized();
    if (a.cwiseAbs().maxCoeff() > 1.0 || b.cwiseAbs().maxCoeff() > 1.0) return false;
    s.links.reference.push_back(0);
    s.links.xy_ref.push_back(a + Eigen::Vector2d(noise(rng), noise(rng)));
    s.links.xy_cur.push_back(b + Eigen::Vector2d(noise(rng), noise(rng)));
    return true;
  };
  while (s.ground < ground_points)
    s.ground += add(Eigen::Vector3d(2.0 + 8.0 * u(rng), -3.0 + 6.0 * u(rng), 0.0));
  while (s.wall_below < 30)
    s.wall_below += add(Eigen::Vector3d(5.0, -3.0 + 6.0 * u(rng), 0.2 + 1.0 * u(rng)));
  for (int above = 0; above < 20;)
    above += add(Eigen::Vector3d(5.0, -3.0 + 6.0 * u(rng), 1.8 + 1.0 * u(rng)));
  return s;
}

// The true pose with its translation since `ref` scaled by `share` (a wrong length).
Rigid3d WithLengthShare(const Rigid3d& truth, const Rigid3d& ref, double share) {
  const Rigid3d rel = truth * ref.Inverse();
  return Rigid3d(rel.rotation, share * rel.translation) * ref;
}

GroundLengthEstimate GroundLength(const GroundScene& s, const std::vector<uint8_t>& use,
                                  const Eigen::Vector4d& plane, double share) {
  return GroundLengthOfMotion(s.links, use, plane, s.ref, WithLengthShare(s.truth, s.ref, share),
                              320.0, 5.0 * kDeg, 1.5, 0.2);
}

TEST(PoseEstimator, GroundGivesTheLengthOfAMotion) {
  const Eigen::Vector4d ground(0.0, 0.0, 1.0, 0.0);
  for (uint32_t seed = 1; seed <= 5; ++seed) {
    const GroundScene s = MakeGroundScene(seed, 0.0, 60);
    const double truth_length = (s.truth * s.ref.Inverse()).translation.norm();
    // From a pose half or twice as long, with the true rotation and direction.
    const GroundLengthEstimate g = GroundLength(s, {}, ground, 0.5);
    ASSERT_TRUE(g.ok) << seed;
    EXPECT_NEAR(g.length, truth_length, 1e-9) << seed;
    EXPECT_NEAR(GroundLength(s, {}, ground, 2.0).length, truth_length, 1e-9) << seed;
    // The ground's links agree (and a few of the wall's near its foot, within 1.5 px);
    // the points above the horizon are no candidates, nor rays within 5 deg of it.
    EXPECT_GE(g.support, s.ground) << seed;
    EXPECT_LE(g.support, s.ground + 10) << seed;
    EXPECT_GE(g.candidates, s.ground + 20) << seed;
    EXPECT_LE(g.candidates, s.ground + s.wall_below) << seed;
    EXPECT_LT(std::max(g.support_shorter, g.support_longer), 0.5 * g.support)
        << seed;  // the views tell the length
    EXPECT_TRUE(GroundLengthIsUsable(g, SlamOptions())) << seed;
    // Only the used links count.
    std::vector<uint8_t> use(s.links.xy_ref.size(), 1);
    for (int i = 0; i < s.ground; i += 2) use[static_cast<size_t>(i)] = 0;
    const GroundLengthEstimate half = GroundLength(s, use, ground, 0.5);
    EXPECT_EQ(half.support, g.support - s.ground / 2) << seed;
    EXPECT_EQ(half.candidates, g.candidates - s.ground / 2) << seed;
    // Against a plane 20 % too high (map units), the length is 20 % short: the cue is only
    // as good as the plane.
    EXPECT_NEAR(GroundLength(s, {}, Eigen::Vector4d(0.0, 0.0, 1.0, -0.3), 0.5).length,
                0.8 * truth_length, 1e-9)
        << seed;
  }
}

TEST(PoseEstimator, GroundLengthWithNoiseAndWithoutGround) {
  const Eigen::Vector4d ground(0.0, 0.0, 1.0, 0.0);
  int wall_refused = 0;
  for (uint32_t seed = 1; seed <= 5; ++seed) {
    const GroundScene s = MakeGroundScene(seed, 0.5, 60);
    const double truth_length = (s.truth * s.ref.Inverse()).translation.norm();
    const GroundLengthEstimate g = GroundLength(s, {}, ground, 0.5);
    ASSERT_TRUE(g.ok) << seed;
    EXPECT_NEAR(g.length, truth_length, 0.03 * truth_length) << seed;
    EXPECT_GE(g.support, 0.8 * s.ground) << seed;
    EXPECT_TRUE(GroundLengthIsUsable(g, SlamOptions())) << seed;
    // No ground in view: the wall's rays meet the ground behind it, and the length that
    // fits most of them is 19-70 % too long. The service's checks (too few agree, as a
    // count or a share, or about as many 20 % off) refuse it in four renderings of five;
    // in the fifth 10 of 24 agree, against 7 at 20 % off.
    const GroundScene w = MakeGroundScene(seed, 0.5, 0);
    const GroundLengthEstimate gw = GroundLength(w, {}, ground, 0.5);
    EXPECT_GT(gw.candidates, 15) << seed;
    EXPECT_GT(gw.length / truth_length - 1.0, 0.15) << seed;
    wall_refused += !GroundLengthIsUsable(gw, SlamOptions());
  }
  EXPECT_GE(wall_refused, 4);
  // Not a plane (normal not of unit length), or no motion: no length.
  const GroundScene s = MakeGroundScene(1, 0.0, 60);
  EXPECT_FALSE(GroundLengthOfMotion(s.links, {}, Eigen::Vector4d(0.0, 0.0, 2.0, 0.0), s.ref,
                                    s.truth, 320.0, 0.1, 1.5, 0.2)
                   .ok);
  EXPECT_FALSE(GroundLengthOfMotion(s.links, {}, ground, s.ref, s.ref, 320.0, 0.1, 1.5, 0.2).ok);
}

TEST(PoseEstimator, GroundLengthIsUsableAtEachThreshold) {
  const SlamOptions o;  // 8 links, 0.3 of the candidates, at most 0.75 as many at -+20 %
  GroundLengthEstimate g;
  g.ok = true;
  g.support = 10;
  g.candidates = 30;
  g.support_shorter = 7;
  g.support_longer = 2;
  EXPECT_TRUE(GroundLengthIsUsable(g, o));
  const auto with = [&](const std::function<void(GroundLengthEstimate*)>& change) {
    GroundLengthEstimate x = g;
    change(&x);
    return GroundLengthIsUsable(x, o);
  };
  EXPECT_FALSE(with([](GroundLengthEstimate* x) { x->ok = false; }));
  EXPECT_FALSE(with([](GroundLengthEstimate* x) {
    x->support = 7, x->support_shorter = 2, x->candidates = 20;
  }));  // under 8
  EXPECT_TRUE(with(
      [](GroundLengthEstimate* x) { x->support = 8, x->support_shorter = 2, x->candidates = 20; }));
  EXPECT_FALSE(with([](GroundLengthEstimate* x) { x->candidates = 34; }));  // 10 < 0.3 * 34
  EXPECT_TRUE(with([](GroundLengthEstimate* x) { x->candidates = 33; }));
  EXPECT_FALSE(with([](GroundLengthEstimate* x) { x->support_longer = 8; }));  // 8 > 0.75 * 10
  EXPECT_FALSE(with([](GroundLengthEstimate* x) { x->support_shorter = 8; }));
}

TEST(PoseEstimator, GroundLengthRefusesMismatchedLinks) {
  const Eigen::Vector4d ground(0.0, 0.0, 1.0, 0.0);
  const GroundScene s = MakeGroundScene(1, 0.0, 60);
  const Rigid3d half = WithLengthShare(s.truth, s.ref, 0.5);
  ASSERT_TRUE(GroundLengthOfMotion(s.links, {}, ground, s.ref, half, 320.0, 0.1, 1.5, 0.2).ok);
  EpipolarLinks short_cur = s.links;
  short_cur.xy_cur.pop_back();
  EXPECT_FALSE(GroundLengthOfMotion(short_cur, {}, ground, s.ref, half, 320.0, 0.1, 1.5, 0.2).ok);
  EpipolarLinks bad_ref = s.links;
  bad_ref.reference[3] = 1;  // one reference only
  EXPECT_FALSE(GroundLengthOfMotion(bad_ref, {}, ground, s.ref, half, 320.0, 0.1, 1.5, 0.2).ok);
  const std::vector<uint8_t> short_use(s.links.xy_ref.size() - 1, 1);
  EXPECT_FALSE(
      GroundLengthOfMotion(s.links, short_use, ground, s.ref, half, 320.0, 0.1, 1.5, 0.2).ok);
}

}  // namespace
}  // namespace mbslam
