// Relocalisation costs (slam.relocalization): per lost image, ORB corners of a 640x480
// image and their match against the map's described points; per keyframe, describing the
// points its tracks observe. The EPnP RANSAC that follows the matching is OpenCV's
// solvePnPRansac (slam.reloc_ransac_iterations at most).
//
//   build/bin/relocalization_bench

#include <benchmark/benchmark.h>

#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "services/perception/tracking/orb_features.h"
#include "services/perception/tracking/test_images.h"

namespace {

using mbslam::OrbDescriptor;

using mbslam::testing_images::Texture;  // band-limited random texture, corners everywhere

// Up to `count` corners' descriptors of textured images (a map's described points).
std::vector<OrbDescriptor> MapDescriptors(size_t count) {
  std::vector<OrbDescriptor> all;
  for (int seed = 1; all.size() < count; ++seed) {
    std::vector<Eigen::Vector2f> corners;
    std::vector<OrbDescriptor> d;
    mbslam::DetectOrb(Texture(640, 480, seed), 1000, 10, &corners, &d);
    all.insert(all.end(), d.begin(), d.end());
  }
  all.resize(count);
  return all;
}

void BM_DetectOrb(benchmark::State& state) {
  const cv::Mat image = Texture(640, 480, 100);
  std::vector<Eigen::Vector2f> corners;
  std::vector<OrbDescriptor> d;
  for (auto _ : state) {
    mbslam::DetectOrb(image, static_cast<int>(state.range(0)), 10, &corners, &d);
    benchmark::DoNotOptimize(d.data());
  }
  state.counters["corners"] = static_cast<double>(corners.size());
}
BENCHMARK(BM_DetectOrb)->Arg(500)->Arg(1000)->Unit(benchmark::kMillisecond);

// One lost image's matching: its corners (range 0) against the map's points (range 1).
void BM_MatchOrb(benchmark::State& state) {
  std::vector<Eigen::Vector2f> corners;
  std::vector<OrbDescriptor> query;
  mbslam::DetectOrb(Texture(640, 480, 100), static_cast<int>(state.range(0)), 10, &corners, &query);
  const std::vector<OrbDescriptor> train = MapDescriptors(static_cast<size_t>(state.range(1)));
  size_t matches = 0;
  for (auto _ : state) {
    matches = mbslam::MatchOrb(query, train, 50, 0.8).size();
    benchmark::DoNotOptimize(matches);
  }
  state.counters["pairs"] = static_cast<double>(query.size() * train.size());
}
BENCHMARK(BM_MatchOrb)->Args({1000, 2000})->Args({1000, 10000})->Unit(benchmark::kMillisecond);

// One keyframe's description: 300 tracked points.
void BM_DescribeKeyframe(benchmark::State& state) {
  const cv::Mat image = Texture(640, 480, 100);
  std::vector<Eigen::Vector2f> points;
  cv::RNG rng(5);
  for (int i = 0; i < 300; ++i)
    points.emplace_back(rng.uniform(20.f, 620.f), rng.uniform(20.f, 460.f));
  std::vector<OrbDescriptor> d;
  std::vector<uint8_t> valid;
  for (auto _ : state) {
    mbslam::DescribeOrbAt(image, points, &d, &valid);
    benchmark::DoNotOptimize(d.data());
  }
}
BENCHMARK(BM_DescribeKeyframe)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
