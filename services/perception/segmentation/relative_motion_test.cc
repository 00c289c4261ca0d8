#include "services/perception/segmentation/relative_motion.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace mbslam {
namespace {

void MakeScene(const Rigid3d& cam_n_from_cam_r, int n, double noise_norm, std::mt19937* rng,
               std::vector<Eigen::Vector2d>* xr, std::vector<Eigen::Vector2d>* xn) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), z(2.0, 10.0);
  std::normal_distribution<double> g(0.0, noise_norm);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p(u(*rng) * 3, u(*rng) * 2, z(*rng));
    const Eigen::Vector3d q = cam_n_from_cam_r * p;
    xr->push_back(p.hnormalized() + Eigen::Vector2d(g(*rng), g(*rng)));
    xn->push_back(q.hnormalized() + Eigen::Vector2d(g(*rng), g(*rng)));
  }
}

// The analytic derivative of the epipolar distance against central differences of
// EpipolarDistance over left perturbations, on random motions and points.
TEST(RelativeMotion, EpipolarDistanceJacobianMatchesNumeric) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    Vector6d xi;
    for (int k = 0; k < 6; ++k) xi[k] = (k < 3 ? 0.5 : 0.2) * u(rng);
    Rigid3d T = Rigid3d::Exp(xi);
    T.translation.normalize();
    const Eigen::Vector2d xr(0.5 * u(rng), 0.4 * u(rng)), xn(0.5 * u(rng), 0.4 * u(rng));
    const Eigen::Matrix3d R = T.RotationMatrix();
    Eigen::Matrix<double, 1, 6> J;
    const double d = EpipolarDistanceAndJacobian(R, Hat(T.translation) * R, xr, xn, &J);
    EXPECT_NEAR(d, EpipolarDistance(Hat(T.translation) * R, xr, xn), 1e-14);
    constexpr double h = 1e-6;
    for (int k = 0; k < 6; ++k) {
      Vector6d dxi = Vector6d::Zero();
      dxi[k] = h;
      const Rigid3d Tp = Rigid3d::Exp(dxi) * T, Tm = Rigid3d::Exp(-dxi) * T;
      const double numeric = (EpipolarDistance(Hat(Tp.translation) * Tp.RotationMatrix(), xr, xn) -
                              EpipolarDistance(Hat(Tm.translation) * Tm.RotationMatrix(), xr, xn)) /
                             (2.0 * h);
      worst = std::max(worst, std::abs(numeric - J[k]) / std::max(1.0, std::abs(numeric)));
    }
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(RelativeMotion, RecoversDirectionAndRotation) {
  std::mt19937 rng(1);
  Vector6d xi;
  xi << 0.3, 0.05, 0.1, 0.01, -0.03, 0.02;
  const Rigid3d truth = Rigid3d::Exp(xi);
  std::vector<Eigen::Vector2d> xr, xn;
  MakeScene(truth, 200, 0.5 / 500.0, &rng, &xr, &xn);
  // 20% outliers.
  for (int i = 0; i < 40; ++i) xn[static_cast<size_t>(i)] += Eigen::Vector2d(0.03, -0.02);
  // Both essential matrix backends.
  for (const char* backend : {"mbslam", "opencv"}) {
    SCOPED_TRACE(backend);
    TwoViewOptions options;
    options.essential_backend = backend;
    RelativeMotion m;
    std::vector<uint8_t> inliers;
    ASSERT_TRUE(EstimateRelativeMotion(xr, xn, 500.0, options, &m, &inliers).ok());
    EXPECT_TRUE(m.translation_known);
    EXPECT_LT(RotationDistance(m.cam_n_from_cam_r, truth), 2e-3);
    EXPECT_GT(m.cam_n_from_cam_r.translation.dot(truth.translation.normalized()), 0.995);
    int outliers_flagged = 0;
    for (int i = 0; i < 40; ++i) outliers_flagged += !inliers[static_cast<size_t>(i)];
    EXPECT_GE(outliers_flagged, 38);
    // The covariance is positive and small on the observable directions.
    EXPECT_GT(m.covariance.trace(), 0.0);
    EXPECT_LT(m.covariance.trace(), 1e-2);
  }
}

// A pan with a small sideways step over a near layer (rocks) below a far one (a hillside),
// as in DAVIS' goat: a rotation about the vertical axis slides every point along its
// (horizontal) epipolar line, so the epipolar distances hardly tell the true motion from
// one that puts the far layer behind the cameras. Counts the inliers whose flow puts them
// behind by more than 2 px.
int BehindAfterEstimate(const TwoViewOptions& options, unsigned seed, double* rotation_error) {
  constexpr double f = 854.0;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(-0.5, 0.5), uy(0.0, 0.28), near_z(3.0, 8.0), far_z(100.0, 400.0);
  std::normal_distribution<double> noise(0.0, 0.8 / f);
  const Rigid3d truth(Eigen::Matrix3d(Eigen::AngleAxisd(0.015, Eigen::Vector3d::UnitY())),
                      Eigen::Vector3d(0.2, 0.0, 0.0));
  std::vector<Eigen::Vector2d> xr, xn;
  for (int i = 0; i < 800; ++i) {
    const bool near = i < 250;
    const double z = near ? near_z(rng) : far_z(rng);
    const Eigen::Vector3d p = Eigen::Vector3d(ux(rng), near ? uy(rng) : -uy(rng), 1.0) * z;
    xr.push_back(p.hnormalized() + Eigen::Vector2d(noise(rng), noise(rng)));
    xn.push_back((truth * p).hnormalized() + Eigen::Vector2d(noise(rng), noise(rng)));
  }
  RelativeMotion m;
  std::vector<uint8_t> inliers;
  if (!EstimateRelativeMotion(xr, xn, f, options, &m, &inliers).ok()) return -1;
  *rotation_error = RotationDistance(m.cam_n_from_cam_r, truth);
  const Eigen::Matrix3d R = m.cam_n_from_cam_r.RotationMatrix();
  int behind = 0;
  for (size_t i = 0; i < xr.size(); ++i) {
    const DepthFlow df = DepthFlowOf(R, m.cam_n_from_cam_r.translation, xr[i], xn[i]);
    behind += inliers[i] && df.valid && df.flow < -2.0 / f;
  }
  return behind;
}

TEST(RelativeMotion, FarLayerIsHeldInFront) {
  TwoViewOptions off;
  off.cheirality_refine = false;
  int fixed = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    double e_on = 0.0, e_off = 0.0;
    const int on = BehindAfterEstimate(TwoViewOptions(), seed, &e_on);
    const int without = BehindAfterEstimate(off, seed, &e_off);
    ASSERT_GE(on, 0);
    ASSERT_GE(without, 0);
    if (without > 325) {
      // The plain estimate put most of the inliers (about 650) behind, its rotation off
      // by ~5 mrad: held in front, the rotation is right to well under 1 mrad.
      ++fixed;
      EXPECT_LE(on, 20) << "seed " << seed;
      EXPECT_LT(e_on, 1e-3) << "seed " << seed << " plain " << e_off;
    } else {
      // Fewer behind than the trigger (half the inliers): the estimate is the plain one.
      EXPECT_EQ(on, without) << "seed " << seed;
      EXPECT_EQ(e_on, e_off) << "seed " << seed;
    }
  }
  EXPECT_GE(fixed, 2);  // the scene does fool the plain estimate
}

// Two motions nearly as well supported (TartanAir's start: tracks sliding along edges
// made a wrong direction win the RANSAC by a few inliers): 110 correspondences follow one
// motion, 100 another. Alone the estimate takes the larger; with the other's heading
// expected (TwoViewOptions::heading_keep_ratio) it keeps that one, which explains over
// 90 % as many; a heading that explains few is not kept.
TEST(RelativeMotion, AnExpectedHeadingWinsANearTie) {
  std::mt19937 rng(4);
  Vector6d xa, xb;
  xa << 0.3, 0.0, 0.1, 0.0, 0.01, 0.0;
  xb << -0.1, 0.3, 0.1, 0.01, 0.0, 0.0;
  const Rigid3d a = Rigid3d::Exp(xa), b = Rigid3d::Exp(xb);
  std::vector<Eigen::Vector2d> xr, xn;
  MakeScene(a, 110, 0.3 / 500.0, &rng, &xr, &xn);
  MakeScene(b, 100, 0.3 / 500.0, &rng, &xr, &xn);
  const Eigen::Vector3d ta = a.translation.normalized(), tb = b.translation.normalized();
  RelativeMotion m;
  std::vector<uint8_t> inliers;
  ASSERT_TRUE(EstimateRelativeMotion(xr, xn, 500.0, TwoViewOptions(), &m, &inliers).ok());
  EXPECT_GT(m.cam_n_from_cam_r.translation.dot(ta), 0.99);
  ASSERT_TRUE(EstimateRelativeMotion(xr, xn, 500.0, TwoViewOptions(), &m, &inliers, &tb).ok());
  EXPECT_GT(m.cam_n_from_cam_r.translation.dot(tb), 0.99);
  EXPECT_LT(RotationDistance(m.cam_n_from_cam_r, b), 2e-3);
  TwoViewOptions strict;
  strict.heading_keep_ratio = 0.95;  // 100 of 110 is not enough
  ASSERT_TRUE(EstimateRelativeMotion(xr, xn, 500.0, strict, &m, &inliers, &tb).ok());
  EXPECT_GT(m.cam_n_from_cam_r.translation.dot(ta), 0.99);
  TwoViewOptions off;
  off.heading_keep_ratio = 0.0;
  ASSERT_TRUE(EstimateRelativeMotion(xr, xn, 500.0, off, &m, &inliers, &tb).ok());
  EXPECT_GT(m.cam_n_from_cam_r.translation.dot(ta), 0.99);
}

// The epipolar distances do not see the translation's sign: an expected heading
// opposite to the truth comes out with the sign that puts the points in front.
TEST(RelativeMotion, AnExpectedHeadingTakesTheSignOfPointsInFront) {
  std::mt19937 rng(2);
  Vector6d xi;
  xi << 0.3, 0.05, 0.1, 0.01, -0.03, 0.02;
  const Rigid3d truth = Rigid3d::Exp(xi);
  std::vector<Eigen::Vector2d> xr, xn;
  MakeScene(truth, 200, 0.3 / 500.0, &rng, &xr, &xn);
  const Eigen::Vector3d flipped = -truth.translation.normalized();
  RelativeMotion m;
  std::vector<uint8_t> inliers;
  ASSERT_TRUE(EstimateRelativeMotion(xr, xn, 500.0, TwoViewOptions(), &m, &inliers, &flipped).ok());
  EXPECT_GT(m.cam_n_from_cam_r.translation.dot(truth.translation.normalized()), 0.995);
  EXPECT_LT(RotationDistance(m.cam_n_from_cam_r, truth), 2e-3);
}

TEST(RelativeMotion, PureRotationIsDetected) {
  std::mt19937 rng(2);
  const Rigid3d truth(Eigen::Matrix3d(Eigen::AngleAxisd(0.02, Eigen::Vector3d(0.2, 1, 0).normalized())),
                      Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector2d> xr, xn;
  MakeScene(truth, 150, 0.3 / 500.0, &rng, &xr, &xn);
  RelativeMotion m;
  std::vector<uint8_t> inliers;
  ASSERT_TRUE(EstimateRelativeMotion(xr, xn, 500.0, TwoViewOptions(), &m, &inliers).ok());
  EXPECT_FALSE(m.translation_known);
  EXPECT_LT(RotationDistance(m.cam_n_from_cam_r, truth), 1e-3);
}

TEST(RelativeMotion, SigmaPointsWeightsSumToOne) {
  RelativeMotion m;
  m.covariance = Matrix6d::Identity() * 1e-4;
  m.covariance(0, 0) = 0.0;  // an unobservable direction is skipped
  const auto samples = MotionSigmaPoints(m);
  EXPECT_EQ(samples.size(), 11u);
  double sum = 0.0;
  for (const auto& s : samples) sum += s.weight;
  EXPECT_NEAR(sum, 1.0, 1e-12);
}

// The sampler's seed (mbslam backend): one seed, one result; another seed, another draw.
// A third of the correspondences are outliers in three coherent groups: some draws stop
// on a model a few inliers short of the truth's (seed 2: 88 inliers of about 105, a
// degree off), which is the spread the evaluations see over seeds.
TEST(RelativeMotion, TheSeedChoosesTheDraw) {
  std::mt19937 rng(7);
  Vector6d xi;
  xi << 0.2, -0.05, 0.1, 0.02, 0.01, -0.02;
  const Rigid3d truth = Rigid3d::Exp(xi);
  std::vector<Eigen::Vector2d> xr, xn;
  MakeScene(truth, 150, 0.5 / 500.0, &rng, &xr, &xn);
  for (int i = 0; i < 45; ++i) xn[static_cast<size_t>(i)] += Eigen::Vector2d(0.02 * (i % 3 - 1), 0.03);
  auto estimate = [&](int64_t seed, RelativeMotion* m, std::vector<uint8_t>* inliers) {
    TwoViewOptions options;
    options.ransac_seed = seed;
    ASSERT_TRUE(options.Check());
    ASSERT_TRUE(EstimateRelativeMotion(xr, xn, 500.0, options, m, inliers).ok());
  };
  RelativeMotion a, b;
  std::vector<uint8_t> ia, ib;
  estimate(TwoViewOptions().ransac_seed, &a, &ia);
  estimate(TwoViewOptions().ransac_seed, &b, &ib);
  EXPECT_EQ(ia, ib);
  EXPECT_EQ(a.cam_n_from_cam_r.translation, b.cam_n_from_cam_r.translation);
  EXPECT_EQ(a.cam_n_from_cam_r.rotation.coeffs(), b.cam_n_from_cam_r.rotation.coeffs());
  int differing = 0, close = 0;
  for (int64_t seed : {1, 2, 3, 4, 5}) {
    RelativeMotion m;
    std::vector<uint8_t> inl;
    estimate(seed, &m, &inl);
    const double rot = RotationDistance(m.cam_n_from_cam_r, truth);
    EXPECT_LT(rot, 0.03) << seed;
    EXPECT_GT(m.cam_n_from_cam_r.translation.dot(truth.translation.normalized()), 0.95) << seed;
    close += rot < 3e-3;
    differing += inl != ia || m.cam_n_from_cam_r.translation != a.cam_n_from_cam_r.translation;
  }
  EXPECT_GE(close, 3);
  EXPECT_GT(differing, 0);  // the seed reaches the sampler
  TwoViewOptions bad;
  bad.ransac_seed = -1;
  EXPECT_FALSE(bad.Check());
  bad.ransac_seed = 0x100000000ll;
  EXPECT_FALSE(bad.Check());
}

TEST(RelativeMotion, TooFewPointsIsAnError) {
  std::vector<Eigen::Vector2d> a(5, Eigen::Vector2d::Zero()), b = a;
  RelativeMotion m;
  std::vector<uint8_t> inl;
  EXPECT_FALSE(EstimateRelativeMotion(a, b, 500, TwoViewOptions(), &m, &inl).ok());
}

}  // namespace
}  // namespace mbslam
