#include "services/perception/segmentation/ground_bound.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Geometry>

namespace mbslam {
namespace {

constexpr double kFocal = 500.0;
constexpr double kGroundNoise = 0.7;

// A forward camera 0.8 m above flat ground (camera axes: x right, y down, z ahead),
// pitched down by 3 deg, moving `step` m ahead between the reference and the current
// image and turning 1 deg. Points are observed with `noise_px` of pixel noise.
struct Pair {
  Eigen::Matrix3d R;  // cam_n_from_cam_r
  Eigen::Vector3d t;
  Eigen::Matrix3d cam_from_level;  // the pitch
  double height = 0.8;

  explicit Pair(double step) {
    cam_from_level = Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
    // The camera centre moves `step` along the level forward axis and yaws by 1 deg.
    const Eigen::Matrix3d yaw = Eigen::AngleAxisd(M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
    const Eigen::Vector3d centre_n_in_r = cam_from_level * Eigen::Vector3d(0.0, 0.0, step);
    R = cam_from_level * yaw.transpose() * cam_from_level.transpose();
    t = -R * centre_n_in_r;
  }
  // A level-frame point (x right, y down from the camera, z ahead) seen from both images.
  bool Observe(const Eigen::Vector3d& level, double noise_px, std::mt19937* rng, Eigen::Vector2d* x_r,
               Eigen::Vector2d* x_n) const {
    std::normal_distribution<double> g(0.0, noise_px / kFocal);
    const Eigen::Vector3d pr = cam_from_level * level;
    const Eigen::Vector3d pn = R * pr + t;
    if (pr.z() < 0.5 || pn.z() < 0.5) return false;
    *x_r = pr.hnormalized() + Eigen::Vector2d(g(*rng), g(*rng));
    *x_n = pn.hnormalized() + Eigen::Vector2d(g(*rng), g(*rng));
    return std::abs(x_r->x()) < 0.64 && std::abs(x_r->y()) < 0.48;
  }
};

TEST(PairGround, InverseDepthOfAPointIsExactWithoutNoise) {
  const Pair pair(0.3);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> ux(-3, 3), uy(-1.5, 0.7), uz(2, 25);
  int checked = 0;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d p(ux(rng), uy(rng), uz(rng));
    Eigen::Vector2d xr, xn;
    if (!pair.Observe(p, 0.0, &rng, &xr, &xn)) continue;
    double s = 0.0, sigma = 0.0;
    if (!PairInverseDepth(xr, xn, pair.R, pair.t, 1.0 / kFocal, &s, &sigma)) continue;
    const double z = (pair.cam_from_level * p).z();
    EXPECT_NEAR(s, 1.0 / z, 1e-9 / z);
    EXPECT_GT(sigma, 0.0);
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

// The inverse depth's standard deviation is that of its estimates over noisy draws.
TEST(PairGround, InverseDepthSigmaMatchesItsSpread) {
  const Pair pair(1.5);  // a long step: the current depth differs from the reference one
  std::mt19937 rng(5);
  const double noise_px = 0.7;
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(1.5, 0.8, 4.0), Eigen::Vector3d(-2.0, 0.8, 9.0)}) {
    double sum = 0.0, sum2 = 0.0, sigma_sum = 0.0;
    const int n = 4000;
    // Noise on the current position only, as the model assumes.
    Eigen::Vector2d xr, xn0;
    ASSERT_TRUE(pair.Observe(p, 0.0, &rng, &xr, &xn0));
    std::normal_distribution<double> g(0.0, noise_px / kFocal);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d xn = xn0 + Eigen::Vector2d(g(rng), g(rng));
      double s = 0.0, sigma = 0.0;
      ASSERT_TRUE(PairInverseDepth(xr, xn, pair.R, pair.t, noise_px / kFocal, &s, &sigma));
      sum += s;
      sum2 += s * s;
      sigma_sum += sigma;
    }
    const double mean = sum / n, spread = std::sqrt(sum2 / n - mean * mean);
    EXPECT_NEAR(sigma_sum / n, spread, 0.2 * spread) << p.transpose();
    EXPECT_NEAR(mean, 1.0 / (pair.cam_from_level * p).z(), 3.0 * spread / std::sqrt(n) + 1e-3 * mean);
  }
}

struct Observations {
  std::vector<Eigen::Vector2d> xr, xn;
};

void AddGround(const Pair& pair, int n, std::mt19937* rng, Observations* obs) {
  std::uniform_real_distribution<double> ux(-6, 6), uz(2.0, 30.0);
  for (int i = 0; i < n; ++i) {
    Eigen::Vector2d xr, xn;
    if (pair.Observe(Eigen::Vector3d(ux(*rng), pair.height, uz(*rng)), kGroundNoise, rng, &xr, &xn)) {
      obs->xr.push_back(xr);
      obs->xn.push_back(xn);
    }
  }
}

// A cloud of static points above the ground (buildings, trees, ...).
void AddCloud(const Pair& pair, int n, std::mt19937* rng, Observations* obs) {
  std::uniform_real_distribution<double> ux(-10, 10), uy(-4, 0.7), uz(4, 40);
  for (int i = 0; i < n; ++i) {
    Eigen::Vector2d xr, xn;
    if (pair.Observe(Eigen::Vector3d(ux(*rng), uy(*rng), uz(*rng)), 0.7, rng, &xr, &xn)) {
      obs->xr.push_back(xr);
      obs->xn.push_back(xn);
    }
  }
}

TEST(PairGround, FindsTheGroundInTheUnitsOfTheTranslation) {
  for (double scale : {1.0, 1.0 / 0.4}) {  // metres, and a two-view estimate's unit translation
    const Pair pair(0.4);
    std::mt19937 rng(2);
    Observations obs;
    AddGround(pair, 250, &rng, &obs);
    AddCloud(pair, 250, &rng, &obs);
    const std::optional<PairGroundPlane> plane = FitPairGroundPlane(
        obs.xr, obs.xn, pair.R, pair.t * scale, kFocal, 1.0, PairGroundOptions());
    ASSERT_TRUE(plane.has_value());
    // m = n / d in the translation's units: d = 0.8 m = 0.8 * scale units. Within 8 %:
    // the inverse depths of noisy positions are a little short (regression dilution;
    // without noise the plane comes out exact), a plane a little too far (looser bounds).
    const Eigen::Vector3d truth = pair.cam_from_level * Eigen::Vector3d::UnitY() / (pair.height * scale);
    EXPECT_LT((plane->m - truth).norm(), 0.08 * truth.norm()) << plane->m.transpose() << " vs " << truth.transpose();
    EXPECT_LT(plane->m.norm(), 1.01 * truth.norm()) << "not nearer than the ground";
    // Only tracks with a precise inverse depth take part (most ground tracks are far).
    EXPECT_GE(plane->inliers, 25);
    EXPECT_GE(plane->inliers, plane->candidates / 2);
  }
}

TEST(PairGround, NoPlaneInACloudOrAFacade) {
  const Pair pair(1.5);  // plenty of parallax: no fit is refused for lack of it
  std::mt19937 rng(3);
  // A cloud reaching below the view (no lowest surface in sight): any slab through it
  // has many of its points beyond it.
  Observations cloud;
  std::uniform_real_distribution<double> cx(-10, 10), cy(-4, 20), cz(3, 40);
  for (int i = 0; i < 1500; ++i) {
    Eigen::Vector2d xr, xn;
    if (pair.Observe(Eigen::Vector3d(cx(rng), cy(rng), cz(rng)), 0.7, &rng, &xr, &xn)) {
      cloud.xr.push_back(xr);
      cloud.xn.push_back(xn);
    }
  }
  EXPECT_FALSE(FitPairGroundPlane(cloud.xr, cloud.xn, pair.R, pair.t, kFocal, 1.0, PairGroundOptions()));
  // A distant facade (fronto-parallel, 30 m) below and above the horizon: a steep plane
  // through it holds its depths within a narrow band.
  Observations facade;
  std::uniform_real_distribution<double> ux(-15, 15), uy(-6, 0.7);
  for (int i = 0; i < 600; ++i) {
    Eigen::Vector2d xr, xn;
    if (pair.Observe(Eigen::Vector3d(ux(rng), uy(rng), 30.0), 0.7, &rng, &xr, &xn)) {
      facade.xr.push_back(xr);
      facade.xn.push_back(xn);
    }
  }
  EXPECT_FALSE(FitPairGroundPlane(facade.xr, facade.xn, pair.R, pair.t, kFocal, 1.0, PairGroundOptions()));
  // A ceiling (a plane above the camera) is not the ground, however well it fits.
  Observations ceiling;
  std::uniform_real_distribution<double> cx2(-6, 6), cz2(2.0, 30.0);
  for (int i = 0; i < 400; ++i) {
    Eigen::Vector2d xr, xn;
    if (pair.Observe(Eigen::Vector3d(cx2(rng), -2.0, cz2(rng)), 0.7, &rng, &xr, &xn)) {
      ceiling.xr.push_back(xr);
      ceiling.xn.push_back(xn);
    }
  }
  PairGroundOptions any_tilt;
  any_tilt.max_tilt_deg = 89.0;
  EXPECT_GT(ceiling.xr.size(), 100u);
  EXPECT_FALSE(FitPairGroundPlane(ceiling.xr, ceiling.xn, pair.R, pair.t, kFocal, 1.0, any_tilt));
  // Non-finite positions are skipped, not fitted.
  Observations with_nan;
  AddGround(pair, 300, &rng, &with_nan);
  for (size_t i = 0; i < with_nan.xr.size(); i += 3) with_nan.xn[i].x() = std::nan("");
  EXPECT_TRUE(FitPairGroundPlane(with_nan.xr, with_nan.xn, pair.R, pair.t, kFocal, 1.0, PairGroundOptions()));
  // No translation: no depth at all.
  Observations ground;
  AddGround(pair, 300, &rng, &ground);
  EXPECT_FALSE(FitPairGroundPlane(ground.xr, ground.xn, pair.R, Eigen::Vector3d::Zero(), kFocal, 1.0,
                                  PairGroundOptions()));
  // The ground itself, with the cloud standing on it, is found.
  Observations scene = ground;
  AddCloud(pair, 300, &rng, &scene);
  EXPECT_TRUE(FitPairGroundPlane(scene.xr, scene.xn, pair.R, pair.t, kFocal, 1.0, PairGroundOptions()));
}

TEST(PairGround, CapsRaysBelowItsHorizonOnly) {
  PairGroundPlane plane;
  plane.m = Eigen::Vector3d(0.0, 1.0, 0.0) / 0.8;  // level camera 0.8 above the ground
  PairGroundOptions o;
  // A ray 10 deg below the horizon meets the ground at 0.8 / tan(10 deg) = 4.54 m.
  const double e = 10.0 * M_PI / 180.0;
  const Eigen::Vector2d down(0.0, std::tan(e));
  const DepthBound b = CapDepthByGround(plane, down, DepthBound(), o);
  const double z = 0.8 / std::tan(e);
  const double expected = z * (1.0 + o.depth_bound_margin +
                               o.depth_bound_tilt_sigma_deg * M_PI / 180.0 / std::tan(e));
  EXPECT_NEAR(b.z_max, expected, 1e-9);
  EXPECT_EQ(b.z_min, 0.0);
  // At or above the horizon, and too near it: no bound.
  EXPECT_TRUE(std::isinf(CapDepthByGround(plane, Eigen::Vector2d(0.2, -0.1), DepthBound(), o).z_max));
  EXPECT_TRUE(std::isinf(CapDepthByGround(plane, Eigen::Vector2d(0.0, 0.02), DepthBound(), o).z_max));
  // A depth from elsewhere beyond the cap is dropped, a nearer one kept.
  const DepthBound far = CapDepthByGround(plane, down, DepthBound{2.0 * expected, 3.0 * expected}, o);
  EXPECT_EQ(far.z_min, 0.0);
  EXPECT_NEAR(far.z_max, expected, 1e-9);
  const DepthBound near = CapDepthByGround(plane, down, DepthBound{1.0, 2.0}, o);
  EXPECT_EQ(near.z_min, 1.0);
  EXPECT_EQ(near.z_max, 2.0);
}

// What the plane is for: a robot on the ground ahead moving along the camera's own
// direction at 0.8x its speed stays on its epipolar lines and looks 5x farther than it
// is. The ground along its rays tells that no static point can be that far.
TEST(PairGround, ItsBoundRevealsAMoverFollowedOnTheGround) {
  const Pair pair(0.4);
  std::mt19937 rng(4);
  Observations statics;
  AddGround(pair, 250, &rng, &statics);
  AddCloud(pair, 250, &rng, &statics);
  const std::optional<PairGroundPlane> plane =
      FitPairGroundPlane(statics.xr, statics.xn, pair.R, pair.t, kFocal, 1.0, PairGroundOptions());
  ASSERT_TRUE(plane.has_value());
  RelativeMotion motion;
  motion.cam_n_from_cam_r = Rigid3d(Eigen::Quaterniond(pair.R), pair.t);
  motion.covariance = Matrix6d::Identity() * 1e-10;
  motion.scale_known = true;
  const std::vector<MotionSample> samples = MotionSigmaPoints(motion);
  StaticLikelihoodOptions lo;
  // Robot points 4 m ahead, 1.2-1.8 m to the right, 0.05-0.3 m above the ground; between
  // the images the robot moves 0.32 m ahead (the camera 0.4 m): it looks 20 m away.
  std::uniform_real_distribution<double> ux(1.2, 1.8), uh(0.05, 0.3);
  int caught = 0, caught_without = 0, n = 0;
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector3d level(ux(rng), pair.height - uh(rng), 4.0);
    const Eigen::Vector3d pr = pair.cam_from_level * level;
    const Eigen::Vector3d moved = pair.cam_from_level * (level + Eigen::Vector3d(0.0, 0.0, 0.32));
    const Eigen::Vector2d xr = pr.hnormalized();
    const Eigen::Vector2d xn = (pair.R * moved + pair.t).hnormalized();
    const DepthBound bound = CapDepthByGround(*plane, xr, DepthBound(), PairGroundOptions());
    caught += ComputeStaticLikelihood(xr, xn, samples, true, true, bound, kFocal, lo).p_static < 0.2;
    caught_without += ComputeStaticLikelihood(xr, xn, samples, true, true, DepthBound(), kFocal, lo).p_static < 0.2;
    ++n;
  }
  EXPECT_GE(caught, n * 9 / 10);
  EXPECT_EQ(caught_without, 0);
  // And the static points are no more often judged moving with the bound than without
  // (one pair with 0.7 px of noise puts a few beyond the epipolar test either way).
  int false_moving = 0, false_moving_without = 0;
  for (size_t i = 0; i < statics.xr.size(); ++i) {
    const DepthBound bound = CapDepthByGround(*plane, statics.xr[i], DepthBound(), PairGroundOptions());
    false_moving += ComputeStaticLikelihood(statics.xr[i], statics.xn[i], samples, true, true, bound, kFocal, lo)
                        .p_static < 0.5;
    false_moving_without +=
        ComputeStaticLikelihood(statics.xr[i], statics.xn[i], samples, true, true, DepthBound(), kFocal, lo)
            .p_static < 0.5;
  }
  EXPECT_LE(false_moving, false_moving_without + static_cast<int>(statics.xr.size()) / 100);
}

}  // namespace
}  // namespace mbslam
