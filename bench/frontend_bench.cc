// Front-end cost per image at 640x480 with ~1000 tracks: the image pyramid (the service's
// preprocessing), feature tracking (KLT, forward-backward and appearance checks, new
// detections) and motion segmentation (world motion, epipolar + FVB likelihood, Bayes
// update, clustering), on a textured scene seen by a camera translating and yawing, with
// a patch moving independently. The time is all three; the
// counters give each part (preprocess_ms, tracking_ms, segmentation_ms).
//
//   build/bin/frontend_bench [--benchmark_...]

#include <benchmark/benchmark.h>

#include <chrono>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "services/perception/geometry/camera.h"
#include "services/perception/segmentation/motion_segmenter.h"
#include "services/perception/tracking/feature_tracker.h"

namespace mbslam {
namespace {

cv::Mat Texture(int w, int h) {
  cv::RNG rng(7);
  cv::Mat noise(h, w, CV_8UC1);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::Mat fine, coarse, out;
  cv::GaussianBlur(noise, fine, cv::Size(0, 0), 1.5);
  cv::GaussianBlur(noise, coarse, cv::Size(0, 0), 6.0);
  cv::addWeighted(fine, 1.0, coarse, 2.0, -128, out);
  return out;
}

// Frame k: the background shifted and slightly rotated, a square region moving faster.
cv::Mat Frame(const cv::Mat& texture, int k) {
  const cv::Point2f centre(texture.cols / 2.0f, texture.rows / 2.0f);
  cv::Mat m = cv::getRotationMatrix2D(centre, 0.05 * k, 1.0 + 0.001 * k);
  m.at<double>(0, 2) += 1.5 * k;
  cv::Mat bg;
  cv::warpAffine(texture, bg, m, texture.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  cv::Mat img = bg(cv::Rect(0, 0, 640, 480)).clone();
  const cv::Rect mover(200 + 4 * (k % 40), 150, 120, 120);
  texture(cv::Rect(700, 500, 120, 120)).copyTo(img(mover));
  return img;
}

void BM_TrackingAndSegmentation(benchmark::State& state) {
  cv::setNumThreads(1);  // OpenCV's own threads off, as in the service's processing thread
  const cv::Mat texture = Texture(960, 720);
  std::vector<cv::Mat> frames;
  for (int k = 0; k < 60; ++k) frames.push_back(Frame(texture, k));
  const CameraIntrinsics K = CameraIntrinsics::Approximate(640, 480, 0.8);
  TrackerOptions to;
  to.max_features = 1000;
  to.klt_threads = static_cast<int>(state.range(0));  // 1: one core; 2: the service's default
  to.klt_backend = state.range(1) == 0 ? "mbslam" : "opencv";
  FeatureTracker tracker(to);
  MotionSegmenter segmenter{SegmentationOptions()};
  int64_t index = 0;
  // Wall time of each part, over the timed images only.
  double preprocess_s = 0.0, tracking_s = 0.0, segmentation_s = 0.0;
  int64_t timed = 0;
  bool timing = false;
  using Clock = std::chrono::steady_clock;
  // Warm up so that the tracks and histories exist.
  auto step = [&](int64_t i) {
    const Clock::time_point tp = Clock::now();
    // As the service's preprocessing stage: a fresh pyramid every image.
    std::vector<cv::Mat> pyramid;
    cv::buildOpticalFlowPyramid(frames[static_cast<size_t>(i % 60)], pyramid, cv::Size(21, 21), 3,
                                /*withDerivatives=*/to.klt_backend == "opencv");
    const Clock::time_point t0 = Clock::now();
    tracker.TrackFrame(pyramid, i, TrackingHints());
    const Clock::time_point t1 = Clock::now();
    SegmenterInput in;
    in.frame_index = i;
    in.width = 640;
    in.height = 480;
    in.focal_px = K.fx;
    in.K = K.K();
    for (const Track& t : tracker.tracks()) {
      if (!t.active()) continue;
      TrackObservation o;
      o.id = t.id;
      o.uv = t.uv.cast<double>();
      o.xy = K.PixelToNormalized(o.uv);
      in.observations.push_back(o);
    }
    const size_t labels = segmenter.Update(in).labels.size();
    if (timing) {
      preprocess_s += std::chrono::duration<double>(t0 - tp).count();
      tracking_s += std::chrono::duration<double>(t1 - t0).count();
      segmentation_s += std::chrono::duration<double>(Clock::now() - t1).count();
      ++timed;
    }
    return labels;
  };
  for (; index < 20; ++index) step(index);
  size_t tracks = 0;
  for (auto _ : state) {
    timing = true;
    tracks = step(index++);
    timing = false;
    if (index % 60 == 0) {  // the sequence wraps: restart cleanly, untimed
      state.PauseTiming();
      tracker.Reset();
      segmenter.Reset();
      for (int w = 0; w < 20; ++w) step(index++);
      state.ResumeTiming();
    }
  }
  state.counters["tracks"] = static_cast<double>(tracks);
  if (timed > 0) {
    state.counters["preprocess_ms"] = 1e3 * preprocess_s / static_cast<double>(timed);
    state.counters["tracking_ms"] = 1e3 * tracking_s / static_cast<double>(timed);
    state.counters["segmentation_ms"] = 1e3 * segmentation_s / static_cast<double>(timed);
  }
}
// Arguments: KLT threads (1 = everything on one core); KLT backend (0 = the project's,
// the default; 1 = OpenCV's calcOpticalFlowPyrLK, for comparison).
BENCHMARK(BM_TrackingAndSegmentation)
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({1, 1})
    ->Args({2, 1})
    ->ArgNames({"klt_threads", "opencv_klt"})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace mbslam

BENCHMARK_MAIN();
