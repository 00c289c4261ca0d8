// Occupancy map costs (thesis sec. 6.3; issue target: <= 20 ms per keyframe for
// 100-300 new points with ranges up to ~20 m, one core).
//
//   build/bin/occupancy_bench [--benchmark_filter=InsertRays]
//   build/bin/occupancy_bench --benchmark_filter=Dense   # with interpolated rays
//
// The scene: a camera walking along a street (x forward, 0.5 m between keyframes) sees
// new static points on the facades left and right and on the ground, 1 to 20 m away,
// mostly ahead. The map is warmed up with 60 keyframes before timing, then keeps growing
// as in a run.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include <octomap/OcTree.h>

#include "services/perception/geometry/rigid3.h"
#include "services/perception/occupancy/dense_rays.h"
#include "services/perception/occupancy/occupancy_map.h"
#include "services/perception/occupancy/octree_ops.h"

namespace {

using mbslam::OccupancyMap;
using mbslam::OccupancyMapOptions;

struct Keyframe {
  Eigen::Vector3d camera;
  std::vector<Eigen::Vector3d> points;
};

// Keyframe k: the camera at x = 0.5 k, 1.6 m high; points on two facades (y = +-6 m)
// and the ground (z = 0), at distances up to max_range_m, uniform in distance.
Keyframe MakeKeyframe(int k, int num_points, double max_range_m, std::mt19937* rng) {
  Keyframe kf;
  kf.camera = Eigen::Vector3d(0.5 * k, 0.0, 1.6);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  kf.points.reserve(static_cast<size_t>(num_points));
  while (static_cast<int>(kf.points.size()) < num_points) {
    const double range = 1.0 + (max_range_m - 1.0) * uni(*rng);
    const double azimuth = (uni(*rng) - 0.5) * 1.6;  // within about +-45 deg of x
    const double surface = uni(*rng);
    Eigen::Vector3d p;
    if (surface < 0.7) {  // facade: the side the azimuth points to
      const double y = azimuth >= 0.0 ? 6.0 : -6.0;
      const double x_offset = std::sqrt(std::max(0.0, range * range - 36.0));
      p = Eigen::Vector3d(kf.camera.x() + x_offset, y, 0.2 + 7.0 * uni(*rng));
    } else {  // ground
      const double horizontal = std::sqrt(std::max(0.0, range * range - 1.6 * 1.6));
      p = Eigen::Vector3d(kf.camera.x() + horizontal * std::cos(azimuth),
                          horizontal * std::sin(azimuth), 0.0);
    }
    if ((p - kf.camera).norm() <= max_range_m) {
      kf.points.push_back(p);
    }
  }
  return kf;
}

OccupancyMapOptions Options(double resolution_m) {
  OccupancyMapOptions options;
  options.resolution_m = resolution_m;
  options.max_range_m = 20.0;
  return options;
}

// Args: points per keyframe, voxel edge (cm).
void BM_InsertRaysPerKeyframe(benchmark::State& state) {
  const int num_points = static_cast<int>(state.range(0));
  const double resolution = 0.01 * static_cast<double>(state.range(1));
  OccupancyMap map(Options(resolution), OccupancyMap::Units::kMetres);
  std::mt19937 rng(7);
  int k = 0;
  for (; k < 60; ++k) {
    const Keyframe kf = MakeKeyframe(k, num_points, 20.0, &rng);
    map.InsertRays(kf.camera, kf.points);
  }
  // Keyframes prepared outside the timed region, a fresh one per iteration.
  std::vector<Keyframe> pending;
  for (auto _ : state) {
    state.PauseTiming();
    if (pending.empty()) {
      for (int i = 0; i < 64; ++i) {
        pending.push_back(MakeKeyframe(k++, num_points, 20.0, &rng));
      }
      std::reverse(pending.begin(), pending.end());
    }
    const Keyframe kf = std::move(pending.back());
    pending.pop_back();
    state.ResumeTiming();
    const mbslam::OccupancyInsertSummary s = map.InsertRays(kf.camera, kf.points);
    benchmark::DoNotOptimize(s.rays_inserted);
  }
  state.counters["points"] = num_points;
  state.counters["resolution_m"] = resolution;
  state.counters["occupied_voxels"] = static_cast<double>(map.NumOccupied());
}
BENCHMARK(BM_InsertRaysPerKeyframe)
    ->ArgsProduct({{100, 200, 300}, {10, 5}})
    ->Unit(benchmark::kMillisecond);

// A map of 200 keyframes x 300 points: what publishing PERCEPTION_OCCUPANCY costs.
void BM_Serialize(benchmark::State& state) {
  const double resolution = 0.01 * static_cast<double>(state.range(0));
  OccupancyMap map(Options(resolution), OccupancyMap::Units::kMetres);
  std::mt19937 rng(11);
  for (int k = 0; k < 200; ++k) {
    const Keyframe kf = MakeKeyframe(k, 300, 20.0, &rng);
    map.InsertRays(kf.camera, kf.points);
  }
  std::string binary;
  for (auto _ : state) {
    if (!map.Serialize(&binary).ok()) {
      state.SkipWithError("Serialize failed");
    }
    benchmark::DoNotOptimize(binary.data());
  }
  state.counters["bytes"] = static_cast<double>(binary.size());
  state.counters["occupied_voxels"] = static_cast<double>(map.NumOccupied());
}
BENCHMARK(BM_Serialize)->Arg(10)->Arg(5)->Unit(benchmark::kMillisecond);

// The same street seen by a 640 x 480 camera (f = 525 px) looking along x: the static
// points in its view (all of them are triangulated for interpolated rays), the first
// `num_new` of them new at this keyframe (measured rays).
struct DenseKeyframe {
  mbslam::Rigid3d cam_from_world;
  Eigen::Vector3d camera;
  std::vector<Eigen::Vector3d> seen;
  std::vector<Eigen::Vector3d> fresh;
};

DenseKeyframe MakeDenseKeyframe(int k, int num_seen, int num_new, std::mt19937* rng) {
  DenseKeyframe kf;
  kf.camera = Eigen::Vector3d(0.5 * k, 0.0, 1.6);
  // cam z = world x, cam x = -world y, cam y = -world z.
  Eigen::Matrix3d r;
  r << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  kf.cam_from_world = mbslam::Rigid3d(Eigen::Quaterniond(r), -(r * kf.camera));
  while (static_cast<int>(kf.seen.size()) < num_seen) {
    for (const Eigen::Vector3d& p : MakeKeyframe(k, 64, 20.0, rng).points) {
      const Eigen::Vector3d c = kf.cam_from_world * p;
      if (c.z() > 0.5 && std::abs(525.0 * c.x() / c.z()) < 320.0 && std::abs(525.0 * c.y() / c.z()) < 240.0 &&
          static_cast<int>(kf.seen.size()) < num_seen) {
        kf.seen.push_back(p);
      }
    }
  }
  kf.fresh.assign(kf.seen.begin(), kf.seen.begin() + std::min(num_new, num_seen));
  return kf;
}

// Per keyframe with interpolated rays: triangulation, sampling and the tree update.
// Args: static points seen, voxel edge (cm), new points among them (measured rays; 0
// times the interpolated part alone).
void BM_DenseKeyframe(benchmark::State& state) {
  const int num_seen = static_cast<int>(state.range(0));
  const double resolution = 0.01 * static_cast<double>(state.range(1));
  const int num_new = static_cast<int>(state.range(2));
  OccupancyMap map(Options(resolution), OccupancyMap::Units::kMetres);
  const mbslam::DenseRayOptions& dense = map.options().dense;
  std::mt19937 rng(17);
  auto insert = [&](const DenseKeyframe& kf, mbslam::DenseRayStats* stats) {
    mbslam::DenseRayInput in;
    in.cam_from_world = kf.cam_from_world;
    in.points_in_world = kf.seen;
    in.focal_px = 525.0;
    in.voxel = map.resolution();
    return map.InsertRays(kf.camera, kf.fresh, mbslam::DensifyKeyframe(in, dense, stats));
  };
  int k = 0;
  mbslam::DenseRayStats stats;
  for (; k < 60; ++k) {
    insert(MakeDenseKeyframe(k, num_seen, 150, &rng), &stats);  // warm-up with measured rays
  }
  std::vector<DenseKeyframe> pending;
  double samples = 0.0, rays = 0.0, iterations = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    if (pending.empty()) {
      for (int i = 0; i < 32; ++i) {
        pending.push_back(MakeDenseKeyframe(k++, num_seen, num_new, &rng));
      }
      std::reverse(pending.begin(), pending.end());
    }
    const DenseKeyframe kf = std::move(pending.back());
    pending.pop_back();
    state.ResumeTiming();
    const mbslam::OccupancyInsertSummary s = insert(kf, &stats);
    benchmark::DoNotOptimize(s.rays_inserted);
    samples += stats.samples;
    rays += s.interpolated_inserted;
    iterations += 1.0;
  }
  state.counters["points"] = num_seen;
  state.counters["new_points"] = num_new;
  state.counters["resolution_m"] = resolution;
  state.counters["samples"] = samples / std::max(1.0, iterations);
  state.counters["interp_rays"] = rays / std::max(1.0, iterations);
  state.counters["occupied_voxels"] = static_cast<double>(map.NumOccupied());
}
BENCHMARK(BM_DenseKeyframe)
    ->ArgsProduct({{200, 400, 800}, {10, 5}, {0, 150}})
    ->Unit(benchmark::kMillisecond);

// The one-off rebuild when the map switches to metres: 200 keyframes x 300 rays.
void BM_RescaleRebuild(benchmark::State& state) {
  OccupancyMapOptions options = Options(0.1);
  options.resolution_depth_fraction = 0.0;
  OccupancyMap map(options, OccupancyMap::Units::kUpToScale);
  std::mt19937 rng(13);
  for (int k = 0; k < 200; ++k) {
    const Keyframe kf = MakeKeyframe(k, 300, 20.0, &rng);
    map.InsertRays(kf.camera, kf.points);
  }
  double factor = 1.01;
  for (auto _ : state) {
    if (!map.Rescale(factor, OccupancyMap::Units::kUpToScale).ok()) {
      state.SkipWithError("Rescale failed");
    }
    factor = 1.0 / factor;
  }
  state.counters["rays"] = static_cast<double>(map.num_stored_rays());
}
BENCHMARK(BM_RescaleRebuild)->Unit(benchmark::kMillisecond)->Iterations(3);

// The memory bound's crop (occupancy.max_memory_mb): a copy of the nodes within a box
// around the last camera of a 100-keyframe x 300-point map at 10 cm (~1.3M nodes, the
// default 64 MB bound). Arg: half edge of the box (voxels).
void BM_MemoryBoundCrop(benchmark::State& state) {
  OccupancyMapOptions options = Options(0.1);
  options.max_memory_mb = 0.0;  // unbounded: the crop is timed here
  OccupancyMap map(options, OccupancyMap::Units::kMetres);
  std::mt19937 rng(17);
  Eigen::Vector3d camera = Eigen::Vector3d::Zero();
  for (int k = 0; k < 100; ++k) {
    const Keyframe kf = MakeKeyframe(k, 300, 20.0, &rng);
    map.InsertRays(kf.camera, kf.points);
    camera = kf.camera;
  }
  const octomap::OcTree& tree = *map.tree();
  octomap::OcTreeKey c;
  if (!tree.coordToKeyChecked(octomap::point3d(static_cast<float>(camera.x()), static_cast<float>(camera.y()),
                                               static_cast<float>(camera.z())),
                              c)) {
    state.SkipWithError("camera outside the tree");
    return;
  }
  const int half = static_cast<int>(state.range(0));
  const octomap::OcTreeKey lo(c[0] - half, c[1] - half, c[2] - half);
  const octomap::OcTreeKey hi(c[0] + half, c[1] + half, c[2] + half);
  size_t kept = 0;
  for (auto _ : state) {
    if (state.range(1) == 0) {
      int64_t occupied = 0;
      const auto crop = mbslam::CropOctree(tree, lo, hi, &occupied);
      kept = crop->size();
      benchmark::DoNotOptimize(occupied);
    } else {
      kept = mbslam::CountCropNodes(tree, lo, hi);
    }
  }
  state.counters["nodes"] = static_cast<double>(tree.size());
  state.counters["nodes_kept"] = static_cast<double>(kept);
  state.counters["memory_mb"] = static_cast<double>(map.MemoryBytes()) / (1024.0 * 1024.0);
}
// Second arg: 0 copies, 1 only counts the nodes (how the box is chosen).
BENCHMARK(BM_MemoryBoundCrop)->ArgsProduct({{64, 128}, {0, 1}})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
