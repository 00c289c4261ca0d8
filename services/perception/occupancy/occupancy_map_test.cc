#include "services/perception/occupancy/occupancy_map.h"

#include <gtest/gtest.h>
#include <octomap/OcTree.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "common/config/options_yaml.h"

namespace mbslam {
namespace {

namespace fs = std::filesystem;

OccupancyMapOptions Metric(double resolution, double max_range) {
  OccupancyMapOptions options;
  options.resolution_m = resolution;
  options.max_range_m = max_range;
  return options;
}

// A wall x = wall_x, seen from cameras near x = 0: a grid of points on it, kept a bit
// away from the voxel faces (multiples of 0.1) so that no test depends on rounding.
std::vector<Eigen::Vector3d> WallPoints(double wall_x, double step) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; - 0.987 + i * step <= 1.0; ++i) {
    for (int j = 0; 0.013 + j * step <= 1.5; ++j) {
      points.emplace_back(wall_x, -0.987 + i * step, 0.013 + j * step);
    }
  }
  return points;
}

// Voxel centres at resolution r are at (k + 0.5) r; keep test points clear of faces.
Eigen::Vector3d Center(double r, int i, int j, int k) {
  return r * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
}

bool OccupiedNear(const OccupancyMap& map, const Eigen::Vector3d& p, double r) {
  for (int i = -1; i <= 1; ++i) {
    for (int j = -1; j <= 1; ++j) {
      for (int k = -1; k <= 1; ++k) {
        if (map.IsOccupied(p + r * Eigen::Vector3d(i, j, k))) {
          return true;
        }
      }
    }
  }
  return false;
}

TEST(OccupancyMap, RaysClearFreeSpaceAndMarkTheirEnds) {
  const double r = 0.1;
  OccupancyMap map(Metric(r, 20.0), OccupancyMap::Units::kMetres);
  ASSERT_TRUE(map.IsResolutionFixed());
  EXPECT_DOUBLE_EQ(map.resolution(), r);
  const Eigen::Vector3d camera = Center(r, 0, 0, 0);
  const Eigen::Vector3d end = Center(r, 50, 0, 0);  // 5 m ahead along x
  const OccupancyInsertSummary s = map.InsertRays(camera, {end});
  EXPECT_EQ(s.rays_inserted, 1);
  EXPECT_EQ(s.rays_rejected, 0);
  EXPECT_EQ(s.rays_truncated, 0);

  ASSERT_TRUE(map.Occupancy(end).has_value());
  EXPECT_NEAR(*map.Occupancy(end), 0.7, 1e-6);  // one hit
  EXPECT_TRUE(map.IsOccupied(end));
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d p = Center(r, i, 0, 0);
    ASSERT_TRUE(map.Occupancy(p).has_value()) << "voxel " << i;
    EXPECT_NEAR(*map.Occupancy(p), 0.4, 1e-6) << "voxel " << i;  // one miss
    EXPECT_FALSE(map.IsOccupied(p));
  }
  // Behind the end and beside the ray nothing is known.
  EXPECT_FALSE(map.Occupancy(Center(r, 52, 0, 0)).has_value());
  EXPECT_FALSE(map.Occupancy(Center(r, 20, 3, 0)).has_value());
  EXPECT_FALSE(map.IsOccupied(Center(r, 52, 0, 0)));
  EXPECT_EQ(map.NumOccupied(), 1);
  ASSERT_EQ(map.OccupiedVoxelCenters().size(), 1u);
  EXPECT_TRUE(map.OccupiedVoxelCenters()[0].isApprox(end, 1e-5));
}

TEST(OccupancyMap, WallSeenFromSeveralViewpoints) {
  const double r = 0.1;
  OccupancyMap map(Metric(r, 20.0), OccupancyMap::Units::kMetres);
  for (int view = 0; view < 5; ++view) {
    const Eigen::Vector3d camera(0.0, -0.5 + 0.25 * view, 0.8);
    map.InsertRays(camera, WallPoints(4.02, 0.1));
  }
  // Every occupied voxel is on the wall, and every wall point is occupied.
  for (const Eigen::Vector3d& c : map.OccupiedVoxelCenters()) {
    EXPECT_NEAR(c.x(), 4.05, 1e-4);
  }
  for (const Eigen::Vector3d& p : WallPoints(4.02, 0.1)) {
    EXPECT_TRUE(map.IsOccupied(p)) << p.transpose();
  }
  // The space between the cameras and the wall is free.
  for (int i = 0; i < 11; ++i) {
    const double x = 0.55 + 0.3 * i;
    const auto p = map.Occupancy(Eigen::Vector3d(x, 0.02, 0.83));
    ASSERT_TRUE(p.has_value()) << x;
    EXPECT_LT(*p, 0.5) << x;
  }
}

TEST(OccupancyMap, SameTreeAsOctomapInsertPointCloud) {
  for (const bool discretize : {false, true}) {
    OccupancyMapOptions options = Metric(0.1, 6.0);
    options.discretize = discretize;
    OccupancyMap map(options, OccupancyMap::Units::kMetres);
    octomap::OcTree reference(0.1);
    for (int view = 0; view < 6; ++view) {
      const Eigen::Vector3d camera(0.01 + 0.4 * view, 0.2 * view - 0.5, 0.81);
      std::vector<Eigen::Vector3d> points = WallPoints(3.0 + 0.7 * view, 0.03);
      for (const Eigen::Vector3d& p : WallPoints(9.0, 0.2)) {
        points.push_back(p);  // beyond range
      }
      map.InsertRays(camera, points);
      octomap::Pointcloud cloud;
      for (const Eigen::Vector3d& p : points) {
        cloud.push_back(p.x(), p.y(), p.z());
      }
      reference.insertPointCloud(cloud, octomap::point3d(camera.x(), camera.y(), camera.z()), 6.0,
                                 false, discretize);
    }
    ASSERT_EQ(map.tree()->size(), reference.size()) << discretize;
    std::ostringstream a, b;
    map.tree()->writeBinaryConst(a);
    reference.writeBinaryConst(b);
    EXPECT_EQ(a.str(), b.str()) << discretize;
    int64_t occupied = 0;
    for (auto it = reference.begin_leafs(); it != reference.end_leafs(); ++it) {
      if (reference.isNodeOccupied(*it)) {
        occupied += int64_t{1} << (3 * (16 - it.getDepth()));
      }
    }
    EXPECT_EQ(map.NumOccupied(), occupied) << discretize;
  }
}

TEST(OccupancyMap, MaxRangeBoundsTheRay) {
  const double r = 0.1;
  OccupancyMap map(Metric(r, 3.0), OccupancyMap::Units::kMetres);
  const Eigen::Vector3d camera = Center(r, 0, 0, 0);
  const OccupancyInsertSummary s =
      map.InsertRays(camera, {Center(r, 100, 0, 0), Center(r, 0, 20, 0)});
  EXPECT_EQ(s.rays_inserted, 2);
  EXPECT_EQ(s.rays_truncated, 1);
  // The long ray: free up to 3 m, nothing known beyond, its end is not occupied.
  for (int i = 0; i < 29; ++i) {
    const auto p = map.Occupancy(Center(r, i, 0, 0));
    ASSERT_TRUE(p.has_value()) << i;
    EXPECT_LT(*p, 0.5);
  }
  EXPECT_FALSE(map.Occupancy(Center(r, 35, 0, 0)).has_value());
  EXPECT_FALSE(map.Occupancy(Center(r, 100, 0, 0)).has_value());
  // The short ray (2 m) is a normal measurement. A point beyond the tree's coordinate
  // range is fine when the range bound keeps the ray inside.
  EXPECT_EQ(map.InsertRays(camera, {Eigen::Vector3d(1e9, 0.05, 0.05)}).rays_truncated, 1);
  EXPECT_TRUE(map.IsOccupied(Center(r, 0, 20, 0)));
  EXPECT_EQ(map.NumOccupied(), 1);
}

TEST(OccupancyMap, RejectsBadPoints) {
  OccupancyMap map(Metric(0.1, 0.0), OccupancyMap::Units::kMetres);  // unbounded range
  const Eigen::Vector3d camera(0.01, 0.02, 0.03);
  const OccupancyInsertSummary s =
      map.InsertRays(camera, {Eigen::Vector3d(NAN, 0, 0), camera, Eigen::Vector3d(1e9, 0, 0),
                              Eigen::Vector3d(2.0, 0.02, 0.03)});
  EXPECT_EQ(s.rays_rejected, 3);
  EXPECT_EQ(s.rays_inserted, 1);
  EXPECT_EQ(
      map.InsertRays(Eigen::Vector3d(INFINITY, 0, 0), {Eigen::Vector3d(1, 0, 0)}).rays_rejected, 1);
  EXPECT_EQ(map.NumOccupied(), 1);
  EXPECT_LT(map.max_range(), 0.0);
  EXPECT_FALSE(map.IsOccupied(Eigen::Vector3d(NAN, 0, 0)));
  EXPECT_FALSE(map.Occupancy(Eigen::Vector3d(NAN, 0, 0)).has_value());
}

TEST(OccupancyMap, SerializeRoundTripsThroughReadBinary) {
  OccupancyMap map(Metric(0.1, 20.0), OccupancyMap::Units::kMetres);
  for (int view = 0; view < 4; ++view) {
    map.InsertRays(Eigen::Vector3d(0.01, 0.3 * view + 0.01, 0.51),
                   WallPoints(3.02 + 0.4 * view, 0.07));
  }
  std::string binary;
  ASSERT_TRUE(map.Serialize(&binary).ok());
  EXPECT_EQ(binary.rfind("# Octomap OcTree binary file", 0), 0u);

  // The same bytes as OcTree::writeBinary on the tree itself.
  octomap::OcTree copy(*map.tree());
  std::ostringstream expected;
  ASSERT_TRUE(copy.writeBinary(expected));
  EXPECT_EQ(binary, expected.str());

  octomap::OcTree read(0.5);
  std::istringstream in(binary);
  ASSERT_TRUE(read.readBinary(in));
  EXPECT_DOUBLE_EQ(read.getResolution(), 0.1);
  int64_t occupied = 0;
  for (auto it = read.begin_leafs(); it != read.end_leafs(); ++it) {
    if (read.isNodeOccupied(*it)) {
      occupied += int64_t{1} << (3 * (16 - it.getDepth()));
    }
  }
  EXPECT_EQ(occupied, map.NumOccupied());
  EXPECT_GT(occupied, 100);
  for (const Eigen::Vector3d& c : map.OccupiedVoxelCenters()) {
    const octomap::OcTreeNode* node = read.search(c.x(), c.y(), c.z());
    ASSERT_NE(node, nullptr);
    EXPECT_TRUE(read.isNodeOccupied(node));
  }
  const Eigen::Vector3d free_point(1.05, 0.35, 0.55);
  const octomap::OcTreeNode* free_node =
      read.search(free_point.x(), free_point.y(), free_point.z());
  ASSERT_NE(free_node, nullptr);
  EXPECT_FALSE(read.isNodeOccupied(free_node));
  // Serialising did not turn the map itself into its maximum-likelihood version (which
  // would clamp every free voxel to clamping_min).
  ASSERT_TRUE(map.Occupancy(free_point).has_value());
  EXPECT_LT(*map.Occupancy(free_point), 0.5);
  EXPECT_GT(*map.Occupancy(free_point), OccupancyMapOptions().clamping_min + 1e-3);
}

TEST(OccupancyMap, SaveBtLoadsWithOctomap) {
  OccupancyMap map(Metric(0.05, 20.0), OccupancyMap::Units::kMetres);
  map.InsertRays(Eigen::Vector3d(0.01, 0.01, 0.5), WallPoints(2.0, 0.05));
  const fs::path dir = fs::temp_directory_path() / ("mbslam_occ_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string path = (dir / "map.bt").string();
  ASSERT_TRUE(map.SaveBt(path).ok());
  // Nothing but the file itself is left in the folder (the temporary was renamed).
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 1);
  octomap::OcTree loaded(path);
  EXPECT_DOUBLE_EQ(loaded.getResolution(), 0.05);
  EXPECT_GT(loaded.getNumLeafNodes(), 0u);
  for (const Eigen::Vector3d& p : WallPoints(2.0, 0.05)) {
    const octomap::OcTreeNode* node = loaded.search(p.x(), p.y(), p.z());
    ASSERT_NE(node, nullptr);
    EXPECT_TRUE(loaded.isNodeOccupied(node));
  }
  // A bad path is a status, not a crash.
  EXPECT_FALSE(map.SaveBt((dir / "missing" / "map.bt").string()).ok());
  fs::remove_all(dir);
}

TEST(OccupancyMap, RescaleKeepsTheGeometry) {
  OccupancyMapOptions options = Metric(0.1, 20.0);
  options.resolution_depth_fraction = 0.0;  // up to scale, fixed voxel edge in map units
  OccupancyMap map(options, OccupancyMap::Units::kUpToScale);
  ASSERT_TRUE(map.IsResolutionFixed());
  for (int view = 0; view < 3; ++view) {
    map.InsertRays(Eigen::Vector3d(0.01, 0.2 * view, 0.51), WallPoints(3.03, 0.1));
  }
  const std::vector<Eigen::Vector3d> before = map.OccupiedVoxelCenters();
  const int64_t occupied = map.NumOccupied();
  ASSERT_GT(occupied, 50);
  const int64_t revision = map.revision();

  // Staying up to scale: the same tree, scaled.
  ASSERT_TRUE(map.Rescale(2.0, OccupancyMap::Units::kUpToScale).ok());
  EXPECT_GT(map.revision(), revision);
  EXPECT_NEAR(map.resolution(), 0.2, 1e-12);
  EXPECT_NEAR(map.max_range(), 40.0, 1e-12);
  EXPECT_EQ(map.NumOccupied(), occupied);
  for (const Eigen::Vector3d& c : before) {
    EXPECT_TRUE(map.IsOccupied(2.0 * c)) << c.transpose();
  }
  EXPECT_LT(*map.Occupancy(Eigen::Vector3d(2.0, 0.4, 1.0)), 0.5);

  // To metres: voxel edge and range bound from the options, geometry kept to a voxel.
  ASSERT_TRUE(map.Rescale(0.75, OccupancyMap::Units::kMetres).ok());
  EXPECT_EQ(map.units(), OccupancyMap::Units::kMetres);
  EXPECT_DOUBLE_EQ(map.resolution(), 0.1);
  EXPECT_DOUBLE_EQ(map.max_range(), 20.0);
  for (const Eigen::Vector3d& c : before) {
    EXPECT_TRUE(OccupiedNear(map, 1.5 * c, 0.1)) << c.transpose();
  }
  for (const Eigen::Vector3d& c : map.OccupiedVoxelCenters()) {
    EXPECT_NEAR(c.x(), 1.5 * 3.03, 0.1);
  }

  EXPECT_FALSE(map.Rescale(0.0, OccupancyMap::Units::kMetres).ok());
  EXPECT_FALSE(map.Rescale(NAN, OccupancyMap::Units::kMetres).ok());
  EXPECT_FALSE(map.Rescale(-1.0, OccupancyMap::Units::kMetres).ok());
  EXPECT_DOUBLE_EQ(map.resolution(), 0.1);
}

TEST(OccupancyMap, UpToScaleResolutionFromMedianDepth) {
  OccupancyMapOptions options;
  options.resolution_depth_fraction = 0.02;
  options.max_range_depth_multiple = 3.0;
  options.min_rays_for_resolution = 100;
  OccupancyMap map(options, OccupancyMap::Units::kUpToScale);
  EXPECT_FALSE(map.IsResolutionFixed());
  // 60 rays of length 10 and 50 of length 30: median 10 once 100 have arrived.
  std::vector<Eigen::Vector3d> near, far;
  for (int i = 0; i < 60; ++i) {
    near.emplace_back(10.0, 0.001 * i, 0.0);
  }
  for (int i = 0; i < 50; ++i) {
    far.emplace_back(30.0, 0.001 * i, 0.0);
  }
  const Eigen::Vector3d camera = Eigen::Vector3d::Zero();
  OccupancyInsertSummary s = map.InsertRays(camera, near);
  EXPECT_EQ(s.rays_buffered, 60);
  EXPECT_EQ(s.rays_inserted, 0);
  EXPECT_FALSE(map.IsResolutionFixed());
  std::string binary;
  EXPECT_FALSE(map.Serialize(&binary).ok());
  EXPECT_EQ(map.NumOccupied(), 0);
  EXPECT_FALSE(map.Occupancy(near[0]).has_value());

  s = map.InsertRays(camera, far);
  EXPECT_EQ(s.rays_inserted, 110);
  ASSERT_TRUE(map.IsResolutionFixed());
  EXPECT_NEAR(map.resolution(), 0.2, 1e-4);
  EXPECT_NEAR(map.max_range(), 30.0, 1e-2);
  EXPECT_TRUE(map.IsOccupied(near[0]));
  EXPECT_TRUE(map.Serialize(&binary).ok());

  // A map in metres from the start uses the options directly.
  OccupancyMap metric(options, OccupancyMap::Units::kMetres);
  EXPECT_TRUE(metric.IsResolutionFixed());
  EXPECT_DOUBLE_EQ(metric.resolution(), options.resolution_m);
}

TEST(OccupancyMap, RescaleBeforeTheResolutionIsFixed) {
  OccupancyMapOptions options;
  options.min_rays_for_resolution = 10;
  OccupancyMap map(options, OccupancyMap::Units::kUpToScale);
  map.InsertRays(Eigen::Vector3d::Zero(), {Eigen::Vector3d(2.0, 0.01, 0.01)});
  ASSERT_TRUE(map.Rescale(3.0, OccupancyMap::Units::kUpToScale).ok());
  EXPECT_FALSE(map.IsResolutionFixed());
  ASSERT_TRUE(map.Rescale(1.0, OccupancyMap::Units::kMetres).ok());
  ASSERT_TRUE(map.IsResolutionFixed());
  EXPECT_DOUBLE_EQ(map.resolution(), options.resolution_m);
  EXPECT_TRUE(map.IsOccupied(Eigen::Vector3d(6.0, 0.03, 0.03)));
}

TEST(OccupancyMap, StoredRaysAreBounded) {
  OccupancyMapOptions options = Metric(0.1, 20.0);
  options.max_stored_rays = 250;
  OccupancyMap map(options, OccupancyMap::Units::kMetres);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 100; ++i) {
    points.emplace_back(3.0, 0.05 * i, 0.0);
  }
  for (int k = 0; k < 3; ++k) {
    map.InsertRays(Eigen::Vector3d(0.0, 0.0, 0.1 * k), points);
  }
  EXPECT_EQ(map.num_stored_rays(), 200);
  EXPECT_EQ(map.rays_forgotten(), 100);

  options.max_stored_rays = 0;
  OccupancyMap none(options, OccupancyMap::Units::kMetres);
  none.InsertRays(Eigen::Vector3d::Zero(), points);
  EXPECT_EQ(none.num_stored_rays(), 0);
  EXPECT_GT(none.NumOccupied(), 0);
}

TEST(OccupancyMap, MemoryEstimateFollowsTheTree) {
  OccupancyMap map(Metric(0.05, 10.0), OccupancyMap::Units::kMetres);
  for (int s = 0; s < 10; ++s) {
    map.InsertRays(Eigen::Vector3d(0.3 * s, 0.0, 0.0), WallPoints(6.0 + 0.3 * s, 0.05));
  }
  const octomap::OcTree* tree = map.tree();
  ASSERT_NE(tree, nullptr);
  // OctoMap's own count (nodes and child arrays, without the allocator's overhead) is a
  // lower bound; the estimate adds the allocator's share and stays within 2x of it.
  const double octomap_bytes = static_cast<double>(tree->memoryUsage());
  EXPECT_GE(static_cast<double>(map.MemoryBytes()), octomap_bytes);
  EXPECT_LE(static_cast<double>(map.MemoryBytes()), 2.5 * octomap_bytes);
  const double inner_share =
      1.0 - static_cast<double>(tree->getNumLeafNodes()) / static_cast<double>(tree->size());
  EXPECT_LT(inner_share, 0.4);
}

TEST(OccupancyMap, MemoryBoundCropsAroundTheCamera) {
  OccupancyMapOptions bounded = Metric(0.05, 6.0);
  bounded.max_memory_mb = 4.0;
  bounded.keep_half_edge_voxels = 100;  // 5 m
  OccupancyMap map(bounded, OccupancyMap::Units::kMetres);
  OccupancyMap unbounded(Metric(0.05, 6.0), OccupancyMap::Units::kMetres);
  // The camera drives 40 m along x past a wall 3 m to its side.
  Eigen::Vector3d camera;
  int64_t max_unbounded = 0;
  for (int s = 0; s <= 80; ++s) {
    camera = Eigen::Vector3d(0.5 * s, 0.0, 0.0);
    std::vector<Eigen::Vector3d> points;
    for (double x = -2.0; x <= 2.0; x += 0.05) {
      for (double z = -0.5; z <= 0.5; z += 0.25) points.emplace_back(camera.x() + x, 3.02, z);
    }
    map.InsertRays(camera, points);
    unbounded.InsertRays(camera, points);
    EXPECT_LE(map.MemoryBytes(), 4 * 1024 * 1024) << "step " << s;
    max_unbounded = std::max(max_unbounded, unbounded.MemoryBytes());
  }
  EXPECT_GT(map.crops(), 0);
  EXPECT_GT(map.occupied_voxels_dropped(), 0);
  EXPECT_GT(map.rays_forgotten(), 0);
  EXPECT_GT(max_unbounded, 8 * 1024 * 1024);
  // Near the camera the bounded map is the unbounded one; the start of the drive is gone.
  EXPECT_TRUE(map.IsOccupied(Eigen::Vector3d(camera.x(), 3.02, 0.0)));
  int same = 0, checked = 0;
  for (double x = camera.x() - 3.0; x <= camera.x(); x += 0.05) {
    for (double y = 0.0; y <= 3.02; y += 0.25) {
      const Eigen::Vector3d p(x, y, 0.0);
      ++checked;
      same += map.Occupancy(p) == unbounded.Occupancy(p);
    }
  }
  EXPECT_EQ(same, checked);
  EXPECT_FALSE(map.Occupancy(Eigen::Vector3d(0.0, 3.02, 0.0)).has_value());
  EXPECT_TRUE(unbounded.IsOccupied(Eigen::Vector3d(0.0, 3.02, 0.0)));
  EXPECT_LT(map.NumOccupied(), unbounded.NumOccupied());
  // A rebuild after a rescale starts from the kept rays only and stays bounded.
  ASSERT_TRUE(map.Rescale(1.0, OccupancyMap::Units::kMetres).ok());
  EXPECT_LE(map.MemoryBytes(), 4 * 1024 * 1024);
  EXPECT_TRUE(map.IsOccupied(Eigen::Vector3d(camera.x(), 3.02, 0.0)));
}

TEST(OccupancyMapOptions, CheckAndYaml) {
  OccupancyMapOptions options;
  EXPECT_TRUE(options.Check());
  options.prob_hit = 0.4;
  EXPECT_FALSE(options.Check());
  options = OccupancyMapOptions();
  options.resolution_m = 0.0;
  EXPECT_FALSE(options.Check());

  OccupancyMapOptions loaded;
  ASSERT_TRUE(
      LoadOptionsFromYamlText("resolution_m: 0.05\nmax_range_m: 8\ndiscretize: true\n", "", &loaded)
          .ok());
  EXPECT_DOUBLE_EQ(loaded.resolution_m, 0.05);
  EXPECT_DOUBLE_EQ(loaded.max_range_m, 8.0);
  EXPECT_TRUE(loaded.discretize);
  EXPECT_FALSE(LoadOptionsFromYamlText("prob_miss: 0.7\n", "", &loaded).ok());
  EXPECT_NE(OptionsToYaml(OccupancyMapOptions()).find("resolution_depth_fraction"),
            std::string::npos);

  // A map made with bad options falls back to the defaults instead of failing later.
  OccupancyMapOptions bad;
  bad.resolution_m = -1.0;
  OccupancyMap map(bad, OccupancyMap::Units::kMetres);
  EXPECT_DOUBLE_EQ(map.resolution(), OccupancyMapOptions().resolution_m);
}

}  // namespace
}  // namespace mbslam
