// Known answers for the camera metrics (issue 3, "what it must show" 2): a trajectory
// perturbed by a known similarity and known noise gives the expected ATE and RPE.

#include "tools/eval/camera_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tools/eval/alignment.h"
#include "tools/eval/perturb.h"

namespace mbslam {
namespace eval {
namespace {

// A smooth 3D trajectory (a wobbly loop) at 30 Hz.
Trajectory MakeTruth(int n) {
  Trajectory t;
  for (int i = 0; i < n; ++i) {
    const double s = 0.05 * i;
    const Eigen::Vector3d p(4.0 * std::cos(s), 3.0 * std::sin(s), 0.5 * std::sin(3.0 * s) + 1.5);
    const Eigen::Quaterniond q(Eigen::AngleAxisd(s + 0.3 * std::sin(s), Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(0.2 * std::cos(2 * s), Eigen::Vector3d::UnitX()));
    t.push_back(
        {1600000000000000 + static_cast<int64_t>(std::llround(i * 1e6 / 30.0)), Rigid3d(q, p)});
  }
  return t;
}

Sim3d KnownSimilarity() {
  Sim3d s;
  s.scale = 2.7;
  s.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, -2, 0.5).normalized()));
  s.translation = Eigen::Vector3d(3.0, -1.0, 7.0);
  return s;
}

TEST(OrientationAlignment, RecoversSimilarityOfAStraightPath) {
  // A camera driving straight and turning its head: positions on one line.
  const Sim3d S = KnownSimilarity();
  std::vector<Rigid3d> src, dst;
  for (int i = 0; i < 30; ++i) {
    const Eigen::Quaterniond q(Eigen::AngleAxisd(0.02 * i, Eigen::Vector3d(0.3, 1.0, 0.1).normalized()));
    src.emplace_back(q, Eigen::Vector3d(0.5 * i, 0.0, 0.0));
    dst.push_back(S * src.back());
  }
  std::vector<Eigen::Vector3d> ps, pd;
  for (size_t i = 0; i < src.size(); ++i) {
    ps.push_back(src[i].translation);
    pd.push_back(dst[i].translation);
  }
  Sim3d est;
  EXPECT_FALSE(UmeyamaAlignment(ps, pd, true, &est).ok());  // rotation about the line unknown
  ASSERT_TRUE(OrientationAlignment(src, dst, true, &est).ok());
  EXPECT_NEAR(est.scale, S.scale, 1e-10);
  EXPECT_LT(est.rotation.angularDistance(S.rotation), 1e-10);
  EXPECT_LT((est.translation - S.translation).norm(), 1e-9);
  // The ATE of the exact copy is zero with this fallback.
  Trajectory e, g;
  for (size_t i = 0; i < src.size(); ++i) {
    e.push_back({static_cast<int64_t>(i) * 100000, src[i]});
    g.push_back({static_cast<int64_t>(i) * 100000, dst[i]});
  }
  AteResult ate;
  ASSERT_TRUE(ComputeAte(e, g, AteOptions(), &ate).ok());
  EXPECT_TRUE(ate.orientation_aligned);
  EXPECT_LT(ate.translation.rmse, 1e-9);
}

TEST(Umeyama, RecoversSimilarityExactly) {
  std::mt19937 rng(4);
  std::normal_distribution<double> n(0.0, 3.0);
  std::vector<Eigen::Vector3d> src, dst;
  const Sim3d S = KnownSimilarity();
  for (int i = 0; i < 50; ++i) {
    src.emplace_back(n(rng), n(rng), n(rng));
    dst.push_back(S * src.back());
  }
  Sim3d est;
  ASSERT_TRUE(UmeyamaAlignment(src, dst, true, &est).ok());
  EXPECT_NEAR(est.scale, S.scale, 1e-12);
  EXPECT_LT(est.rotation.angularDistance(S.rotation), 1e-12);
  EXPECT_LT((est.translation - S.translation).norm(), 1e-10);
  // Rigid alignment of a pure rotation + translation.
  Sim3d rigid = S;
  rigid.scale = 1.0;
  for (size_t i = 0; i < src.size(); ++i) {
    dst[i] = rigid * src[i];
  }
  ASSERT_TRUE(UmeyamaAlignment(src, dst, false, &est).ok());
  EXPECT_DOUBLE_EQ(est.scale, 1.0);
  EXPECT_LT(est.rotation.angularDistance(rigid.rotation), 1e-12);
  // A reflection is never returned.
  for (size_t i = 0; i < src.size(); ++i) {
    dst[i] = Eigen::Vector3d(src[i].x(), src[i].y(), -src[i].z());
  }
  ASSERT_TRUE(UmeyamaAlignment(src, dst, true, &est).ok());
  EXPECT_NEAR(est.rotation.toRotationMatrix().determinant(), 1.0, 1e-12);
  // Degenerate inputs are refused.
  EXPECT_FALSE(UmeyamaAlignment({src[0], src[1]}, {dst[0], dst[1]}, true, &est).ok());
  EXPECT_FALSE(UmeyamaAlignment(
                   {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(2, 2, 2)},
                   {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(2, 2, 2)},
                   true, &est)
                   .ok());
}

TEST(Ate, KnownSimilarityWithoutNoiseIsZero) {
  const Trajectory gt = MakeTruth(300);
  TrajectoryPerturbation p;
  p.gt_from_est = KnownSimilarity();
  Trajectory est;
  double expected = -1.0;
  ASSERT_TRUE(PerturbTrajectory(gt, p, &est, &expected).ok());
  EXPECT_EQ(expected, 0.0);
  AteResult r;
  ASSERT_TRUE(ComputeAte(est, gt, AteOptions(), &r).ok());
  EXPECT_EQ(r.pairs.size(), 300u);
  EXPECT_LT(r.translation.rmse, 1e-9);
  EXPECT_LT(r.rotation_deg.max, 1e-7);
  EXPECT_NEAR(r.gt_from_est.scale, 2.7, 1e-12);
  // Without scale, the same estimate is far off; without alignment, further still.
  AteOptions se3;
  se3.alignment = "se3";
  AteResult r_se3;
  ASSERT_TRUE(ComputeAte(est, gt, se3, &r_se3).ok());
  EXPECT_GT(r_se3.translation.rmse, 1.0);
  AteOptions none;
  none.alignment = "none";
  AteResult r_none;
  ASSERT_TRUE(ComputeAte(est, gt, none, &r_none).ok());
  EXPECT_GT(r_none.translation.rmse, r_se3.translation.rmse);
}

// The noise is constructed so that S is the exact optimum: ATE = RMS of the noise.
TEST(Ate, KnownSimilarityAndNoiseGiveExactAte) {
  const Trajectory gt = MakeTruth(400);
  for (double sigma : {0.01, 0.05, 0.2}) {
    TrajectoryPerturbation p;
    p.gt_from_est = KnownSimilarity();
    p.noise_sigma_m = sigma;
    p.seed = 11;
    Trajectory est;
    double expected = 0.0;
    ASSERT_TRUE(PerturbTrajectory(gt, p, &est, &expected).ok());
    EXPECT_NEAR(expected, sigma * std::sqrt(3.0), 0.15 * sigma * std::sqrt(3.0));
    AteResult r;
    ASSERT_TRUE(ComputeAte(est, gt, AteOptions(), &r).ok());
    EXPECT_NEAR(r.translation.rmse, expected, 1e-9 * std::max(1.0, expected)) << sigma;
    EXPECT_NEAR(r.gt_from_est.scale, 2.7, 1e-9);
    EXPECT_LT(r.gt_from_est.rotation.angularDistance(p.gt_from_est.rotation), 1e-9);
    EXPECT_LT((r.gt_from_est.translation - p.gt_from_est.translation).norm(), 1e-8);
  }
}

// Plain (not orthogonalised) noise: alignment can only lower the error, by the few
// degrees of freedom it absorbs.
TEST(Ate, PlainNoiseGivesAboutTheNoiseRms) {
  const Trajectory gt = MakeTruth(1000);
  TrajectoryPerturbation p;
  p.gt_from_est = KnownSimilarity();
  p.noise_sigma_m = 0.03;
  p.exact = false;
  Trajectory est;
  double noise_rms = 0.0;
  ASSERT_TRUE(PerturbTrajectory(gt, p, &est, &noise_rms).ok());
  AteResult r;
  ASSERT_TRUE(ComputeAte(est, gt, AteOptions(), &r).ok());
  EXPECT_LE(r.translation.rmse, noise_rms + 1e-12);
  EXPECT_GT(r.translation.rmse, 0.99 * noise_rms);
  EXPECT_NEAR(r.gt_from_est.scale, 2.7, 0.01);
}

TEST(Ate, AssociationWithDropsAndOffsets) {
  const Trajectory gt = MakeTruth(100);
  Trajectory est;
  for (size_t i = 0; i < gt.size(); ++i) {
    if (i % 4 == 3) {
      continue;  // a quarter not tracked
    }
    est.push_back({gt[i].utime + 5000, gt[i].pose});
  }
  AteOptions o;
  o.alignment = "none";
  AteResult r;
  ASSERT_TRUE(ComputeAte(est, gt, o, &r).ok());
  EXPECT_EQ(r.pairs.size(), 75u);
  EXPECT_LT(r.translation.max, 1e-12);
  EXPECT_DOUBLE_EQ(FractionTracked(est, gt, 20000), 0.75);
  EXPECT_DOUBLE_EQ(FractionTracked(est, gt, 1000), 0.0);
  o.max_time_diff_us = 1000;
  EXPECT_FALSE(ComputeAte(est, gt, o, &r).ok());
  o.alignment = "bogus";
  EXPECT_FALSE(ComputeAte(est, gt, o, &r).ok());
}

// RPE: every relative motion of the estimate is the true one followed by a known
// perturbation, and expressed at a known scale.
TEST(Rpe, KnownRelativeErrors) {
  const Trajectory gt = MakeTruth(200);
  const double scale = 0.4;  // est units per metre
  Vector6d xi;
  xi << 0.02, -0.01, 0.005, 0.003, 0.0, -0.004;
  const Rigid3d perturbation = Rigid3d::Exp(xi);
  Trajectory est;
  Rigid3d pose = gt[0].pose;
  est.push_back({gt[0].utime, Rigid3d(pose.rotation, scale * pose.translation)});
  for (size_t i = 1; i < gt.size(); ++i) {
    const Rigid3d rel = gt[i - 1].pose.Inverse() * gt[i].pose * perturbation;
    pose = pose * rel;
    est.push_back({gt[i].utime, Rigid3d(pose.rotation, scale * pose.translation)});
  }
  const auto pairs = AssociateByTime(est, gt, 1000);
  RpeOptions o;
  o.est_scale = 1.0 / scale;
  RpeResult r;
  ASSERT_TRUE(ComputeRpe(est, gt, pairs, o, &r).ok());
  EXPECT_EQ(r.translation.count, 199);
  EXPECT_NEAR(r.translation.rmse, perturbation.translation.norm(), 1e-9);
  EXPECT_NEAR(r.translation.max - r.translation.min, 0.0, 1e-9);
  EXPECT_NEAR(r.rotation_deg.rmse, xi.tail<3>().norm() * 180.0 / M_PI, 1e-7);
  // Over a time delta of 1 s (30 frames) the errors compound but stay measurable.
  o.delta_us = 1000000;
  ASSERT_TRUE(ComputeRpe(est, gt, pairs, o, &r).ok());
  EXPECT_EQ(r.translation.count, 200 - 30);
  EXPECT_GT(r.translation.rmse, 5.0 * perturbation.translation.norm());
  // The exact trajectory has zero RPE.
  ASSERT_TRUE(ComputeRpe(gt, gt, AssociateByTime(gt, gt, 0), RpeOptions(), &r).ok());
  EXPECT_LT(r.translation.max, 1e-12);
}

TEST(ErrorStats, Values) {
  const ErrorStats s = ErrorStats::From({3.0, 1.0, 2.0, 4.0});
  EXPECT_EQ(s.count, 4);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));
  EXPECT_EQ(ErrorStats::From({}).count, 0);
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
