// Bearing-only tracking costs (thesis ch. 5; issue target: the filters of 5 objects with
// 1000 particles each <= 3 ms per frame on one core).
//
//   build/bin/objects_bench [--benchmark_filter=Update]
//
// Five objects from the synthetic scenes (car and hand-held cameras, following and
// crossing targets), all cues on (depth bound, ground plane, size bound, and SfM feedback
// in the sfm:1 runs),
// velocities already seated (the sequences are 3 s long: the filters are re-initialised,
// untimed, after each pass). One iteration is one image: every filter's Update, and with
// ...AndOutputs also its Estimate, the object's extent and the predicted volumes (5
// horizons).

#include <benchmark/benchmark.h>

#include "common/util/parallel_for.h"

#include <array>
#include <memory>
#include <vector>

#include "services/perception/objects/bot_simulation.h"

namespace {

using mbslam::BearingOnlyTracker;
using mbslam::BearingOnlyTrackerOptions;
using mbslam::BotSimCamera;
using mbslam::BotSimOptions;
using mbslam::BotSimSequence;
using mbslam::BotSimTarget;

struct Scene {
  std::vector<BotSimSequence> sequences;  // one per object
};

const Scene& Scenes() {
  static const Scene* scene = [] {
    auto* s = new Scene;
    const std::array<std::pair<BotSimCamera, BotSimTarget>, 5> kinds = {{
        {BotSimCamera::kCar, BotSimTarget::kFollowing},
        {BotSimCamera::kCar, BotSimTarget::kCrossing},
        {BotSimCamera::kHandHeld, BotSimTarget::kFollowing},
        {BotSimCamera::kHandHeld, BotSimTarget::kCrossing},
        {BotSimCamera::kCar, BotSimTarget::kFollowing},
    }};
    uint64_t seed = 1;
    for (const auto& kind : kinds) {
      BotSimOptions o;
      o.camera = kind.first;
      o.target = kind.second;
      o.duration_s = 3.0;
      o.seed = seed++;
      BotSimSequence seq;
      if (!mbslam::SimulateBotSequence(o, &seq).ok()) std::abort();
      s->sequences.push_back(std::move(seq));
    }
    return s;
  }();
  return *scene;
}

// The trackers, initialised and run past the velocity seating and the start of SfM.
struct Filters {
  std::vector<std::unique_ptr<BearingOnlyTracker>> trackers;
  std::vector<mbslam::ObjectExtentEstimator> extents;
  size_t frame = 0;
};

void Reset(int particles, bool sfm, Filters* f) {
  const Scene& scene = Scenes();
  BearingOnlyTrackerOptions options;
  options.num_particles = particles;
  options.cues.sfm_feedback = sfm;
  f->trackers.clear();
  f->extents.assign(scene.sequences.size(), mbslam::ObjectExtentEstimator());
  for (size_t i = 0; i < scene.sequences.size(); ++i) {
    f->trackers.push_back(
        std::make_unique<BearingOnlyTracker>(options, static_cast<int64_t>(i + 1)));
    if (!f->trackers.back()->Initialize(scene.sequences[i].frames[0].observation).ok())
      std::abort();
  }
  // Warm up: one second (seating at 0.3 s, SfM from 0.5 s).
  for (f->frame = 1; f->frame <= 30; ++f->frame) {
    for (size_t i = 0; i < scene.sequences.size(); ++i) {
      const mbslam::BotSimFrame& frame = scene.sequences[i].frames[f->frame];
      if (frame.visible && !f->trackers[i]->Update(frame.observation).ok()) std::abort();
    }
  }
}

void RunFilters(benchmark::State& state, bool outputs) {
  const int particles = static_cast<int>(state.range(0));
  const bool sfm = state.range(1) != 0;
  const int threads = static_cast<int>(state.range(2));
  const Scene& scene = Scenes();
  const size_t frames = scene.sequences[0].frames.size();
  Filters f;
  Reset(particles, sfm, &f);
  for (auto _ : state) {
    if (f.frame >= frames) {
      state.PauseTiming();
      Reset(particles, sfm, &f);
      state.ResumeTiming();
    }
    // The objects' filters are independent: ObjectTracking runs them on objects.threads.
    mbslam::ParallelFor(scene.sequences.size(), threads, [&](size_t i) {
      const mbslam::BotSimFrame& frame = scene.sequences[i].frames[f.frame];
      benchmark::DoNotOptimize(frame.visible ? f.trackers[i]->Update(frame.observation).ok()
                                             : f.trackers[i]->Predict(frame.utime).ok());
      if (outputs) {
        const mbslam::BotEstimate e = f.trackers[i]->Estimate();
        static_cast<void>(f.extents[i].Update(frame.cam_from_world, frame.observation.track_xy,
                                              frame.observation.xy, e.depth,
                                              scene.sequences[i].ground_plane.plane.normal));
        benchmark::DoNotOptimize(f.trackers[i]->PredictVolumes(f.extents[i].extent()));
      }
    });
    ++f.frame;
  }
  state.counters["objects"] = static_cast<double>(scene.sequences.size());
  state.counters["particles"] = particles;
  state.counters["threads"] = threads;
}

void BM_FiveObjectsUpdate(benchmark::State& state) { RunFilters(state, false); }
void BM_FiveObjectsUpdateAndOutputs(benchmark::State& state) { RunFilters(state, true); }

// Args: particles per object, SfM feedback on (objects reconstructed) or off (only tracked:
// the sampled motion model with the depth bound, ground plane and size bound).
BENCHMARK(BM_FiveObjectsUpdate)
    ->ArgNames({"particles", "sfm", "threads"})
    ->Args({1000, 1, 1})
    ->Args({1000, 0, 1})
    ->Args({500, 0, 1})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FiveObjectsUpdateAndOutputs)
    ->ArgNames({"particles", "sfm", "threads"})
    ->Args({1000, 1, 1})
    ->Args({1000, 0, 1})
    ->Args({1000, 0, 2})
    ->Unit(benchmark::kMillisecond);

void BM_GroundPlaneRansac(benchmark::State& state) {
  const BotSimSequence& seq = Scenes().sequences[0];
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  for (auto _ : state) {
    mbslam::GroundPlaneEstimate estimate;
    benchmark::DoNotOptimize(mbslam::EstimateGroundPlane(seq.static_points, up, &estimate).ok());
  }
  state.counters["points"] = static_cast<double>(seq.static_points.size());
}
BENCHMARK(BM_GroundPlaneRansac)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
