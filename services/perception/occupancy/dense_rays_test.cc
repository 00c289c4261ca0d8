#include "services/perception/occupancy/dense_rays.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "services/perception/occupancy/occupancy_map.h"

namespace mbslam {
namespace {

constexpr double kFocal = 500.0;

// Points on the plane z = z0 + slope * x (camera frame = world frame: the camera at the
// origin looking along +z), at random image positions within |x/z| < hx, |y/z| < hy.
std::vector<Eigen::Vector3d> PlanePoints(int n, double z0, double slope, double x_lo, double x_hi, double hy,
                                         uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(x_lo, x_hi), uy(-hy, hy);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) {
    const double a = ux(rng), b = uy(rng);  // normalised image position
    const double z = z0 / (1.0 - slope * a);  // on z = z0 + slope * x with x = a z
    points.emplace_back(a * z, b * z, z);
  }
  return points;
}

DenseRayInput Input(std::vector<Eigen::Vector3d> points, double voxel) {
  DenseRayInput in;
  in.cam_from_world = Rigid3d();
  in.points_in_world = std::move(points);
  in.focal_px = kFocal;
  in.voxel = voxel;
  return in;
}

bool OccupiedNear(const OccupancyMap& map, const Eigen::Vector3d& p, double r) {
  for (int i = -1; i <= 1; ++i) {
    for (int j = -1; j <= 1; ++j) {
      for (int k = -1; k <= 1; ++k) {
        if (map.IsOccupied(p + r * Eigen::Vector3d(i, j, k))) return true;
      }
    }
  }
  return false;
}

// Fraction of the plane z = z0 + slope * x over the image window |x/z| < 0.25,
// |y/z| < 0.2 (inside the points' spread) that has an occupied voxel within one voxel.
double PlaneRecall(const OccupancyMap& map, double z0, double slope, double r) {
  int found = 0, total = 0;
  for (double a = -0.25; a <= 0.25; a += 0.01) {
    for (double b = -0.2; b <= 0.2; b += 0.01) {
      const double z = z0 / (1.0 - slope * a);
      ++total;
      found += OccupiedNear(map, Eigen::Vector3d(a * z, b * z, z), r) ? 1 : 0;
    }
  }
  return static_cast<double>(found) / total;
}

TEST(DenseRays, SamplesLieOnThePlaneOfTheirTriangle) {
  const double z0 = 5.0, slope = 0.3;
  DenseRayStats stats;
  const std::vector<Eigen::Vector3d> samples =
      DensifyKeyframe(Input(PlanePoints(40, z0, slope, -0.4, 0.4, 0.3, 1), 0.1), DenseRayOptions(), &stats);
  EXPECT_EQ(stats.points, 40);
  EXPECT_GT(stats.triangles, 40);
  EXPECT_GT(stats.triangles_used, 30);
  ASSERT_GT(samples.size(), 500u);
  EXPECT_EQ(stats.samples, static_cast<int>(samples.size()));
  for (const Eigen::Vector3d& p : samples) {
    EXPECT_NEAR(p.z(), z0 + slope * p.x(), 1e-6 * p.z());
  }
}

TEST(DenseRays, DenseRaysRecoverThePlaneSparseOnesDoNot) {
  const double z0 = 5.0, slope = 0.3, r = 0.1;
  const std::vector<Eigen::Vector3d> points = PlanePoints(80, z0, slope, -0.4, 0.4, 0.3, 2);
  OccupancyMapOptions options;
  options.resolution_m = r;
  OccupancyMap sparse(options, OccupancyMap::Units::kMetres);
  OccupancyMap dense(options, OccupancyMap::Units::kMetres);
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  sparse.InsertRays(origin, points);
  const std::vector<Eigen::Vector3d> samples = DensifyKeyframe(Input(points, r), options.dense);
  const OccupancyInsertSummary s = dense.InsertRays(origin, points, samples);
  EXPECT_EQ(s.rays_inserted, 80);
  EXPECT_GT(s.interpolated_inserted, 500);
  EXPECT_EQ(s.interpolated_inserted + s.interpolated_merged, static_cast<int>(samples.size()));
  const double sparse_recall = PlaneRecall(sparse, z0, slope, r);
  const double dense_recall = PlaneRecall(dense, z0, slope, r);
  EXPECT_LT(sparse_recall, 0.6);  // 0.46 measured
  EXPECT_GT(dense_recall, 0.95);  // 0.98 measured
  // And nothing off the plane: every occupied voxel is within a voxel of it.
  for (const Eigen::Vector3d& c : dense.OccupiedVoxelCenters()) {
    const double off = std::abs(c.z() - z0 - slope * c.x()) / std::sqrt(1.0 + slope * slope);
    EXPECT_LT(off, std::sqrt(3.0) * r) << c.transpose();
  }
}

// A foreground plane at 3 m on the left, a background plane at 9 m on the right: the
// triangles across the edge are not sampled, so nothing is put between the two.
std::vector<Eigen::Vector3d> StepPoints() {
  std::vector<Eigen::Vector3d> points = PlanePoints(40, 3.0, 0.0, -0.4, -0.01, 0.3, 3);
  for (const Eigen::Vector3d& p : PlanePoints(40, 9.0, 0.0, 0.01, 0.4, 0.3, 4)) points.push_back(p);
  return points;
}

TEST(DenseRays, DepthDiscontinuityIsNotBridged) {
  DenseRayStats stats;
  const std::vector<Eigen::Vector3d> samples = DensifyKeyframe(Input(StepPoints(), 0.1), DenseRayOptions(), &stats);
  EXPECT_GT(stats.rejected_depth, 3);
  int near = 0, far = 0;
  for (const Eigen::Vector3d& p : samples) {
    EXPECT_TRUE(std::abs(p.z() - 3.0) < 1e-6 || std::abs(p.z() - 9.0) < 1e-6) << p.transpose();
    near += p.z() < 6.0;
    far += p.z() > 6.0;
  }
  EXPECT_GT(near, 100);
  EXPECT_GT(far, 100);

  // The check that does it: with the depth test off, the bridge is filled in (the
  // incidence test alone also catches it unless it is opened too).
  DenseRayOptions loose;
  loose.max_depth_ratio = 10.0;
  loose.max_incidence_deg = 90.0;
  int between = 0;
  for (const Eigen::Vector3d& p : DensifyKeyframe(Input(StepPoints(), 0.1), loose)) {
    between += p.z() > 3.5 && p.z() < 8.5;
  }
  EXPECT_GT(between, 10);
}

TEST(DenseRays, GrazingTrianglesAreSkipped) {
  // A plane seen almost edge-on (normal 87 deg from the view direction).
  const double slope = std::tan((90.0 - 3.0) * M_PI / 180.0);
  DenseRayOptions options;
  options.max_depth_ratio = 1e6;
  DenseRayStats stats;
  // Depth grows quickly with x: keep the image window narrow so the depths stay finite.
  const std::vector<Eigen::Vector3d> points = PlanePoints(30, 5.0, slope, -0.004, 0.004, 0.3, 5);
  DensifyKeyframe(Input(points, 0.1), options, &stats);
  EXPECT_GT(stats.triangles, 10);
  EXPECT_EQ(stats.rejected_incidence, stats.triangles - stats.rejected_edge);
}

TEST(DenseRays, NothingInsideMovingHulls) {
  const std::vector<Eigen::Vector3d> points = PlanePoints(60, 5.0, 0.0, -0.4, 0.4, 0.3, 6);
  DenseRayInput in = Input(points, 0.1);
  // Without a hull, the middle of the image is sampled.
  auto in_box = [](const Eigen::Vector3d& p, double half) {
    return std::abs(p.x() / p.z()) < half && std::abs(p.y() / p.z()) < half;
  };
  int inside = 0;
  for (const Eigen::Vector3d& p : DensifyKeyframe(in, DenseRayOptions())) inside += in_box(p, 0.1);
  EXPECT_GT(inside, 50);

  in.moving_hulls_xy.push_back({{-0.1, -0.1}, {0.1, -0.1}, {0.1, 0.1}, {-0.1, 0.1}});
  DenseRayStats stats;
  const std::vector<Eigen::Vector3d> samples = DensifyKeyframe(in, DenseRayOptions(), &stats);
  EXPECT_GT(stats.rejected_moving, 0);
  EXPECT_GT(samples.size(), 300u);
  for (const Eigen::Vector3d& p : samples) {
    EXPECT_FALSE(in_box(p, 0.1)) << p.transpose();
  }
}

TEST(DenseRays, SpacingFollowsVoxelAndDepthAndTheBudget) {
  const std::vector<Eigen::Vector3d> points = PlanePoints(40, 5.0, 0.0, -0.4, 0.4, 0.3, 7);
  DenseRayOptions options;
  options.max_samples = 1000000;
  const size_t fine = DensifyKeyframe(Input(points, 0.05), options).size();
  const size_t coarse = DensifyKeyframe(Input(points, 0.1), options).size();
  // Samples per area ~ 1 / spacing^2.
  EXPECT_GT(static_cast<double>(fine), 3.0 * static_cast<double>(coarse));
  options.max_samples = 200;
  DenseRayStats stats;
  const size_t capped = DensifyKeyframe(Input(points, 0.05), options, &stats).size();
  EXPECT_LE(capped, 200u);
  EXPECT_GT(capped, 50u);
  EXPECT_GT(stats.spacing_scale, 1.0);
  options.enabled = false;
  EXPECT_TRUE(DensifyKeyframe(Input(points, 0.05), options).empty());
}

TEST(DenseRays, PoseAndFewPoints) {
  // The same plane seen from a moved and turned camera gives the same surface.
  const std::vector<Eigen::Vector3d> in_cam = PlanePoints(40, 5.0, 0.2, -0.4, 0.4, 0.3, 8);
  const Rigid3d world_from_cam(Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 1.0, 0.1).normalized())),
                               Eigen::Vector3d(1.0, -2.0, 0.5));
  std::vector<Eigen::Vector3d> in_world;
  for (const Eigen::Vector3d& p : in_cam) in_world.push_back(world_from_cam * p);
  DenseRayInput in = Input(in_world, 0.1);
  in.cam_from_world = world_from_cam.Inverse();
  const std::vector<Eigen::Vector3d> samples = DensifyKeyframe(in, DenseRayOptions());
  ASSERT_GT(samples.size(), 300u);
  for (const Eigen::Vector3d& w : samples) {
    const Eigen::Vector3d p = in.cam_from_world * w;
    EXPECT_NEAR(p.z(), 5.0 + 0.2 * p.x(), 1e-6 * p.z());
  }
  in.points_in_world.resize(5);
  EXPECT_TRUE(DensifyKeyframe(in, DenseRayOptions()).empty());
}

TEST(DenseRays, DepthSigmaFromParallax) {
  const Eigen::Vector3d point(0.0, 0.0, 10.0), view(0.0, 0.0, 0.0);
  // A 1 m baseline across the ray: sin(parallax) = 1 / sqrt(101).
  EXPECT_NEAR(TriangulationDepthSigma(point, view, {Eigen::Vector3d(1.0, 0.0, 0.0)}, 0.001),
              10.0 * 0.001 * std::sqrt(101.0), 1e-9);
  // The widest parallax counts; a centre on the ray adds nothing.
  EXPECT_NEAR(TriangulationDepthSigma(point, view,
                                      {Eigen::Vector3d(0.0, 0.0, 5.0), Eigen::Vector3d(0.0, 2.0, 0.0),
                                       Eigen::Vector3d(1.0, 0.0, 0.0)},
                                      0.001),
              10.0 * 0.001 * std::sqrt(104.0) / 2.0, 1e-9);
  EXPECT_TRUE(std::isinf(TriangulationDepthSigma(point, view, {}, 0.001)));
  EXPECT_TRUE(std::isinf(TriangulationDepthSigma(point, view, {Eigen::Vector3d(0.0, 0.0, 3.0)}, 0.001)));
}

TEST(DenseRays, UncertainPointsAreNotTriangulated) {
  // A plane whose points on the right have a depth uncertainty of five voxels: only the
  // left, well-placed part is sampled.
  std::vector<Eigen::Vector3d> points = PlanePoints(60, 4.0, 0.0, -0.4, 0.4, 0.3, 9);
  DenseRayInput in = Input(points, 0.1);
  in.depth_sigma.assign(points.size(), 0.05);
  for (size_t i = 0; i < in.points_in_world.size(); ++i) {
    if (in.points_in_world[i].x() > 0.0) in.depth_sigma[i] = 0.5;  // 5 voxels
  }
  DenseRayStats stats;
  const std::vector<Eigen::Vector3d> samples = DensifyKeyframe(in, DenseRayOptions(), &stats);
  EXPECT_GT(stats.uncertain, 15);
  EXPECT_EQ(stats.points + stats.uncertain, 60);
  ASSERT_GT(samples.size(), 100u);
  for (const Eigen::Vector3d& p : samples) EXPECT_LE(p.x(), 0.0) << p.transpose();
  // With no limit they are all used.
  DenseRayOptions all;
  all.max_depth_sigma_voxels = 0.0;
  DensifyKeyframe(in, all, &stats);
  EXPECT_EQ(stats.uncertain, 0);
  EXPECT_EQ(stats.points, 60);
}

TEST(OccupancyMap, InterpolatedRaysGiveAWeakerHitOncePerVoxel) {
  OccupancyMapOptions options;
  options.resolution_m = 0.1;
  options.max_range_m = 20.0;
  options.dense.free_space = true;
  OccupancyMap map(options, OccupancyMap::Units::kMetres);
  // Coordinates clear of the voxel faces (multiples of 0.1), also when doubled.
  const Eigen::Vector3d origin(0.03, 0.03, 0.03);
  const Eigen::Vector3d a(3.03, 0.03, 0.03), b(0.03, 3.03, 0.03), far(30.03, 0.03, 0.03);
  // Three interpolated points in a's voxel, one measured point and one interpolated point
  // in b's voxel, one interpolated point beyond the range bound.
  const OccupancyInsertSummary s =
      map.InsertRays(origin, {b}, {a, a + Eigen::Vector3d(0.01, 0.01, 0.0), a - Eigen::Vector3d(0.0, 0.02, 0.01), b, far});
  EXPECT_EQ(s.rays_inserted, 1);
  EXPECT_EQ(s.interpolated_inserted, 2);
  EXPECT_EQ(s.interpolated_merged, 2);
  EXPECT_EQ(s.interpolated_rejected, 1);
  ASSERT_TRUE(map.Occupancy(a).has_value());
  EXPECT_NEAR(*map.Occupancy(a), options.dense.prob_hit, 1e-4);   // one weak hit
  EXPECT_NEAR(*map.Occupancy(b), options.prob_hit, 1e-4);         // the measured hit wins
  EXPECT_NEAR(*map.Occupancy(Eigen::Vector3d(1.55, 0.03, 0.03)), options.prob_miss, 1e-4);  // free on the way
  EXPECT_FALSE(map.Occupancy(Eigen::Vector3d(25.05, 0.03, 0.03)).has_value());  // nothing beyond the bound
  EXPECT_EQ(map.NumOccupied(), 2);

  // Without free space from interpolated rays, only their ends change.
  options.dense.free_space = false;
  OccupancyMap ends_only(options, OccupancyMap::Units::kMetres);
  ends_only.InsertRays(origin, {}, {a});
  EXPECT_NEAR(*ends_only.Occupancy(a), options.dense.prob_hit, 1e-4);
  EXPECT_FALSE(ends_only.Occupancy(Eigen::Vector3d(1.55, 0.03, 0.03)).has_value());

  // Interpolated rays are stored and survive a rescale rebuild.
  EXPECT_EQ(map.num_stored_rays(), 6);
  ASSERT_TRUE(map.Rescale(2.0, OccupancyMap::Units::kMetres).ok());
  EXPECT_NEAR(*map.Occupancy(2.0 * a), options.dense.prob_hit, 1e-4);
}

TEST(OccupancyMapOptions, DenseOptionsAreChecked) {
  OccupancyMapOptions options;
  EXPECT_TRUE(options.Check());
  options.dense.prob_hit = options.prob_hit + 0.05;
  EXPECT_FALSE(options.Check());
  options = OccupancyMapOptions();
  options.dense.max_depth_ratio = 1.0;
  EXPECT_FALSE(options.Check());
  options = OccupancyMapOptions();
  options.dense.max_incidence_deg = 95.0;
  EXPECT_FALSE(options.Check());
}

}  // namespace
}  // namespace mbslam
