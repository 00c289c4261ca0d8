#include "services/perception/geometry/essential.h"

#include "services/perception/geometry/rigid3.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace mbslam {
namespace {

struct Scene {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;  // unit
  Eigen::Matrix3d E;  // [t]x R, unit norm
  std::vector<Eigen::Vector2d> x_r, x_n;
};

// A random motion and n points 2-20 m in front of both cameras within a 60 deg field.
Scene RandomScene(std::mt19937* rng, int n, double noise = 0.0) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g(0.0, noise > 0.0 ? noise : 1.0);
  Scene s;
  const Eigen::Vector3d axis = Eigen::Vector3d(u(*rng), u(*rng), u(*rng)).normalized();
  s.R = Eigen::AngleAxisd(0.3 * u(*rng), axis).toRotationMatrix();
  s.t = Eigen::Vector3d(u(*rng), u(*rng), 0.5 * u(*rng)).normalized();
  s.E = Hat(s.t) * s.R;
  s.E /= s.E.norm();
  while (static_cast<int>(s.x_r.size()) < n) {
    const double depth = 2.0 + 9.0 * (u(*rng) + 1.0);
    const Eigen::Vector3d p(0.55 * depth * u(*rng), 0.55 * depth * u(*rng), depth);
    const Eigen::Vector3d q = s.R * p + s.t;
    if (q.z() < 1.0) continue;
    Eigen::Vector2d a = p.hnormalized(), b = q.hnormalized();
    if (noise > 0.0) {
      a += Eigen::Vector2d(g(*rng), g(*rng));
      b += Eigen::Vector2d(g(*rng), g(*rng));
    }
    s.x_r.push_back(a);
    s.x_n.push_back(b);
  }
  return s;
}

double DistanceUpToSign(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return std::min((a - b).norm(), (a + b).norm());
}

TEST(FivePointEssentials, EverySolutionIsAnEssentialMatrixThroughThePoints) {
  std::mt19937 rng(7);
  int recovered = 0, trials = 300, solutions = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const Scene s = RandomScene(&rng, 5);
    const std::vector<Eigen::Matrix3d> Es = FivePointEssentials(s.x_r.data(), s.x_n.data());
    ASSERT_FALSE(Es.empty()) << trial;
    ASSERT_LE(Es.size(), 10u);
    ASSERT_EQ(Es.size() % 2, 0u) << "real solutions of a tenth-degree system come in an even number";
    bool found = false;
    for (const Eigen::Matrix3d& E : Es) {
      ++solutions;
      EXPECT_NEAR(E.norm(), 1.0, 1e-9);
      for (int i = 0; i < 5; ++i) {
        EXPECT_LT(std::abs(s.x_n[i].homogeneous().dot(E * s.x_r[i].homogeneous())), 1e-8) << trial;
      }
      // Two equal singular values and a zero one.
      const Eigen::Vector3d sv = Eigen::JacobiSVD<Eigen::Matrix3d>(E).singularValues();
      EXPECT_LT(sv[2], 1e-6) << trial;
      EXPECT_NEAR(sv[0], sv[1], 1e-6) << trial;
      found = found || DistanceUpToSign(E, s.E) < 1e-6;
    }
    recovered += found;
  }
  // The true motion is among the solutions (a few near-degenerate samples may lose it).
  EXPECT_GE(recovered, trials - 3);
  EXPECT_GT(solutions, 2 * trials);
}

// A moving object's tracks span a narrow field of view, and a box's face is a plane: the
// true motion is still among the solutions, to rounding.
TEST(FivePointEssentials, NarrowFieldAndPlanarPoints) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int mode = 0; mode < 2; ++mode) {
    SCOPED_TRACE(mode == 0 ? "narrow field" : "plane");
    int found = 0;
    constexpr int kTrials = 300;
    for (int trial = 0; trial < kTrials; ++trial) {
      const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
      const Eigen::Matrix3d R = Eigen::AngleAxisd(0.05 * u(rng), axis).toRotationMatrix();
      const Eigen::Vector3d t = Eigen::Vector3d(u(rng), u(rng), 0.3 * u(rng)).normalized();
      Eigen::Matrix3d E = Hat(t) * R;
      E /= E.norm();
      Eigen::Vector2d a[5], b[5];
      for (int i = 0; i < 5; ++i) {
        Eigen::Vector3d p;
        if (mode == 0) {
          p = Eigen::Vector3d(0.03 * u(rng), 0.03 * u(rng), 1.0) * (6.0 + 0.5 * u(rng));  // +-1.7 deg at 6 m
        } else {
          p = Eigen::Vector3d(0.5 * u(rng), 0.5 * u(rng), 0.0);
          p.z() = 5.0 + 0.3 * p.x() + 0.2 * p.y();
        }
        a[i] = p.hnormalized();
        b[i] = (R * p + 0.1 * t).hnormalized();
      }
      bool f = false;
      for (const Eigen::Matrix3d& Ei : FivePointEssentials(a, b)) f = f || DistanceUpToSign(Ei, E) < 1e-6;
      found += f;
    }
    EXPECT_GE(found, kTrials - 3);
  }
}

TEST(FivePointEssentials, DegeneratePointsGiveNoFiniteNonsense) {
  // All five correspondences identical: the constraints have rank 1.
  Eigen::Vector2d a[5], b[5];
  for (int i = 0; i < 5; ++i) {
    a[i] = Eigen::Vector2d(0.1, 0.2);
    b[i] = Eigen::Vector2d(0.12, 0.2);
  }
  for (const Eigen::Matrix3d& E : FivePointEssentials(a, b)) {
    EXPECT_TRUE(E.allFinite());
    EXPECT_NEAR(E.norm(), 1.0, 1e-9);
  }
}

TEST(SampsonDistanceSquared, IsTheFirstOrderGeometricError) {
  const Eigen::Matrix3d E = Hat(Eigen::Vector3d(1, 0, 0));  // pure sideways translation: epipolar lines are rows
  // A point displaced vertically by d from its epipolar line: Sampson distance d^2 / 2
  // (the error shared between the two images).
  const double d = 0.01;
  EXPECT_NEAR(SampsonDistanceSquared(E, Eigen::Vector2d(0.1, 0.2), Eigen::Vector2d(0.3, 0.2 + d)), d * d / 2.0, 1e-12);
  EXPECT_EQ(SampsonDistanceSquared(E, Eigen::Vector2d(0.1, 0.2), Eigen::Vector2d(0.3, 0.2)), 0.0);
}

TEST(EstimateEssentialRansac, FindsTheMotionAmongOutliers) {
  std::mt19937 rng(3);
  const double noise = 0.5 / 500.0;  // half a pixel at a 500 px focal length
  for (int trial = 0; trial < 20; ++trial) {
    Scene s = RandomScene(&rng, 300, noise);
    // A third of the correspondences replaced by random ones.
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    std::vector<uint8_t> truth(s.x_r.size(), 1);
    for (size_t i = 0; i < s.x_r.size(); i += 3) {
      s.x_n[i] = Eigen::Vector2d(u(rng), u(rng));
      truth[i] = 0;
    }
    for (const bool msac : {false, true}) {
    SCOPED_TRACE(msac ? "msac" : "inlier count");
    EssentialRansacOptions o;
    o.threshold = 1.5 / 500.0;
    o.msac = msac;
    EssentialRansacResult r;
    ASSERT_TRUE(EstimateEssentialRansac(s.x_r, s.x_n, o, &r).ok());
    EXPECT_LT(DistanceUpToSign(r.E, s.E), 0.05) << trial;
    int true_inliers_found = 0, outliers_taken = 0, true_inliers = 0;
    for (size_t i = 0; i < truth.size(); ++i) {
      true_inliers += truth[i];
      true_inliers_found += truth[i] && r.inliers[i];
      outliers_taken += !truth[i] && r.inliers[i];
    }
    // Unrefined (a noisy sample's model): most, not all, of the true inliers.
    EXPECT_GE(true_inliers_found, 0.85 * true_inliers) << trial;
    EXPECT_LE(outliers_taken, 10) << trial;  // random points that happen to lie near their epipolar lines
    int counted = 0;
    for (uint8_t m : r.inliers) counted += m;
    EXPECT_EQ(counted, r.num_inliers);
    // The adaptive stop: at two thirds inliers far fewer samples than the maximum.
    EXPECT_LT(r.iterations, 200) << trial;
    }
  }
}

TEST(EstimateEssentialRansac, FivePointsTakeOneSampleAndAnInfinitePointIsAnOutlier) {
  std::mt19937 rng(13);
  Scene s = RandomScene(&rng, 100, 0.0005);
  EssentialRansacOptions o;
  o.threshold = 0.003;
  EssentialRansacResult r;
  const std::vector<Eigen::Vector2d> r5(s.x_r.begin(), s.x_r.begin() + 5), n5(s.x_n.begin(), s.x_n.begin() + 5);
  ASSERT_TRUE(EstimateEssentialRansac(r5, n5, o, &r).ok());
  EXPECT_EQ(r.iterations, 1);  // five distinct points: one sample, all inliers
  EXPECT_EQ(r.num_inliers, 5);
  s.x_n[7] = Eigen::Vector2d(std::numeric_limits<double>::infinity(), 0.1);
  for (const bool msac : {false, true}) {
    o.msac = msac;
    ASSERT_TRUE(EstimateEssentialRansac(s.x_r, s.x_n, o, &r).ok()) << msac;
    EXPECT_FALSE(r.inliers[7]) << msac;
    EXPECT_GE(r.num_inliers, 95) << msac;
    EXPECT_LT(DistanceUpToSign(r.E, s.E), 0.05) << msac;
  }
}

TEST(EstimateEssentialRansac, MinimumSamplesAreDrawn) {
  std::mt19937 rng(5);
  const Scene s = RandomScene(&rng, 100, 0.0005);
  EssentialRansacOptions o;
  o.threshold = 0.003;
  EssentialRansacResult r;
  ASSERT_TRUE(EstimateEssentialRansac(s.x_r, s.x_n, o, &r).ok());
  EXPECT_LT(r.iterations, 20);  // all inliers: the adaptive rule stops at once
  o.min_iterations = 40;
  ASSERT_TRUE(EstimateEssentialRansac(s.x_r, s.x_n, o, &r).ok());
  EXPECT_EQ(r.iterations, 40);
  o.max_iterations = 30;  // the maximum bounds the minimum
  ASSERT_TRUE(EstimateEssentialRansac(s.x_r, s.x_n, o, &r).ok());
  EXPECT_EQ(r.iterations, 30);
}

// Among models with the same inliers, MSAC keeps the one that fits them best. With a
// threshold wide enough for every sample's model to take every point, counting keeps the
// first sample's model; MSAC keeps the one with the smallest squared errors.
TEST(EstimateEssentialRansac, MsacPrefersTheBetterFitOfEqualInlierSets) {
  std::mt19937 rng(9);
  const Scene s = RandomScene(&rng, 80, 1.0 / 500.0);
  auto cost = [&](const Eigen::Matrix3d& E) {
    double c = 0.0;
    for (size_t i = 0; i < s.x_r.size(); ++i) c += SampsonDistanceSquared(E, s.x_r[i], s.x_n[i]);
    return c;
  };
  EssentialRansacOptions o;
  o.threshold = 0.2;  // wide: nearly any sample's model explains every point
  o.min_iterations = 100;
  EssentialRansacResult counted, msac;
  ASSERT_TRUE(EstimateEssentialRansac(s.x_r, s.x_n, o, &counted).ok());
  o.msac = true;
  ASSERT_TRUE(EstimateEssentialRansac(s.x_r, s.x_n, o, &msac).ok());
  EXPECT_EQ(counted.num_inliers, 80);
  EXPECT_EQ(msac.num_inliers, 80);
  EXPECT_LT(cost(msac.E), 0.5 * cost(counted.E));
  EXPECT_LT(DistanceUpToSign(msac.E, s.E), DistanceUpToSign(counted.E, s.E));
}

TEST(EstimateEssentialRansac, IsDeterministicAndRefusesTooFewPoints) {
  std::mt19937 rng(11);
  const Scene s = RandomScene(&rng, 60, 0.001);
  EssentialRansacOptions o;
  o.threshold = 0.003;
  EssentialRansacResult a, b;
  ASSERT_TRUE(EstimateEssentialRansac(s.x_r, s.x_n, o, &a).ok());
  ASSERT_TRUE(EstimateEssentialRansac(s.x_r, s.x_n, o, &b).ok());
  EXPECT_EQ(a.E, b.E);
  EXPECT_EQ(a.inliers, b.inliers);
  const std::vector<Eigen::Vector2d> four(s.x_r.begin(), s.x_r.begin() + 4);
  EXPECT_FALSE(EstimateEssentialRansac(four, four, o, &a).ok());
  EXPECT_FALSE(EstimateEssentialRansac(s.x_r, four, o, &a).ok());
  o.confidence = 1.0;
  EXPECT_FALSE(EstimateEssentialRansac(s.x_r, s.x_n, o, &a).ok());
}

}  // namespace
}  // namespace mbslam
