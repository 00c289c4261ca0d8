// mbslam-eval-segmentation: scores the moving-feature labels a perception run
// published (PERCEPTION_TRACKS in its output log) against a simulator sequence's
// ground truth (per-pixel body masks and the bodies' velocities on GROUND_TRUTH).
//
//   mbslam-eval-segmentation --run OUT.lcmlog --sequence SIM_DIR [--settle N] [--name NAME]
//
// A feature is labelled moving when its body is not the static world; it truly moves
// when the mask under it is a body that moves in that frame (a previously static
// object counts as static until it starts). Frames from `settle` frames after each
// mover's appearance are scored. Prints a summary and, last, one JSON line:
//   moving_recall, moving_precision, detection_delay_frames (per object), misclassification
//   (track level, Hungarian), frames_scored; and moving_recall_off_silhouette /
//   moving_precision_off_silhouette: the same without the features closer than
//   --silhouette-px (3) to the boundary between moving and not moving pixels.
// Env EVAL_DUMP_TP / EVAL_DUMP_FP / EVAL_DUMP_FN / EVAL_DUMP_TN set (to any value) print each scored
// feature of that outcome first ("TP frame F id T uv U V body B mask M p P epi E fvb F
// age A"; FP lines add the distance to the nearest moving pixel).

#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/lcm/channels.h"
#include "common/lcm/lcm_log.h"
#include "common/lcm/wire_check.h"
#include "common/util/command_line.h"
#include "mbslam/ground_truth_t.hpp"
#include "mbslam/tracks_t.hpp"
#include "tools/tracks/misclassification.h"

namespace mbslam {
namespace {

int Run(int argc, char** argv) {
  const CommandLineArgs args(argc, argv);
  const std::string run = args.Get("run"), seq = args.Get("sequence"), name = args.Get("name", "sequence");
  const int settle = static_cast<int>(args.GetInt("settle", 10));
  const double silhouette_px = args.GetDouble("silhouette-px", 3.0);
  if (const std::string problems = args.Problems(); !problems.empty()) {
    std::fprintf(stderr, "mbslam-eval-segmentation: %s\nusage: mbslam-eval-segmentation --run OUT.lcmlog --sequence SIM_DIR [--settle N] [--silhouette-px D] [--name NAME]\n",
                 problems.c_str());
    return 2;
  }
  if (!(silhouette_px >= 0.0)) {
    std::fprintf(stderr, "mbslam-eval-segmentation: --silhouette-px must be >= 0\n");
    return 2;
  }
  if (run.empty() || seq.empty()) {
    std::fprintf(stderr, "mbslam-eval-segmentation: --run and --sequence are required\n");
    return 2;
  }
  const ChannelOptions ch;
  // Ground truth: which bodies move in which frame.
  std::vector<LcmLogEvent> gt_events;
  Status s = ReadLcmLog(seq + "/sequence.lcmlog", &gt_events, ch.ground_truth);
  if (!s.ok()) {
    std::fprintf(stderr, "%s\n", s.message().c_str());
    return 1;
  }
  std::map<int64_t, std::set<int>> moving_bodies;  // frame -> bodies moving
  std::map<int, int64_t> first_moving_frame;
  for (const LcmLogEvent& e : gt_events) {
    mbslam::ground_truth_t gt{};
    if (!DecodeLcmMessage(e.data.data(), e.data.size(), &gt).ok()) continue;
    for (const auto& b : gt.bodies) {
      const double v = std::sqrt(b.linear_velocity[0] * b.linear_velocity[0] +
                                 b.linear_velocity[1] * b.linear_velocity[1] +
                                 b.linear_velocity[2] * b.linear_velocity[2]);
      const double w = std::sqrt(b.angular_velocity[0] * b.angular_velocity[0] +
                                 b.angular_velocity[1] * b.angular_velocity[1] +
                                 b.angular_velocity[2] * b.angular_velocity[2]);
      if ((v > 0.02 || w > 0.02) && b.visible) {
        moving_bodies[gt.frame_seq].insert(b.id);
        first_moving_frame.try_emplace(b.id, gt.frame_seq);
      }
    }
  }
  std::vector<LcmLogEvent> events;
  s = ReadLcmLog(run, &events, ch.perception_tracks);
  if (!s.ok() || events.empty()) {
    std::fprintf(stderr, "no PERCEPTION_TRACKS in %s\n", run.c_str());
    return 1;
  }
  int64_t tp = 0, fp = 0, fn = 0, tn = 0, frames = 0;
  // The same away from the movers' silhouettes: features closer than silhouette_px to the
  // boundary between moving and not moving pixels are left out (a corner on the
  // outline, whose patch covers both sides, moves with the outline).
  int64_t tp_off = 0, fp_off = 0, fn_off = 0;
  std::map<int, int64_t> detected_frame;  // true body -> first frame its features were mostly moving with an object
  std::map<int64_t, std::map<int, int>> truth_votes, pred_votes;  // track -> body -> count
  for (const LcmLogEvent& e : events) {
    mbslam::tracks_t t{};
    if (!DecodeLcmMessage(e.data.data(), e.data.size(), &t).ok()) continue;
    char path[64];
    std::snprintf(path, sizeof(path), "/masks/%06lld.png", static_cast<long long>(t.frame_seq));
    const cv::Mat mask = cv::imread(seq + path, cv::IMREAD_UNCHANGED);
    if (mask.empty()) continue;
    const std::set<int>& movers = moving_bodies[t.frame_seq];
    // Distance of every pixel to the nearest truly moving pixel (boundary analysis).
    cv::Mat not_moving(mask.size(), CV_8UC1, cv::Scalar(255));
    for (int y = 0; y < mask.rows; ++y) {
      for (int x = 0; x < mask.cols; ++x) {
        const int b = mask.type() == CV_16UC1 ? mask.at<uint16_t>(y, x) : mask.at<uint8_t>(y, x);
        if (b != 0 && movers.count(b)) not_moving.at<uint8_t>(y, x) = 0;
      }
    }
    cv::Mat dist, dist_in;
    cv::distanceTransform(not_moving, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    // ... and of every moving pixel to the nearest pixel that is not.
    cv::Mat moving_px;
    cv::bitwise_not(not_moving, moving_px);
    cv::distanceTransform(moving_px, dist_in, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    std::map<int, std::pair<int, int>> per_body;  // body -> (features, labelled moving with an object)
    bool scored = false;
    for (const auto& f : t.tracks) {
      if (f.flags & (mbslam::feature_track_t::FLAG_OCCLUDED | mbslam::feature_track_t::FLAG_NEW)) continue;
      const int u = static_cast<int>(std::lround(f.u)), v = static_cast<int>(std::lround(f.v));
      if (u < 0 || v < 0 || u >= mask.cols || v >= mask.rows) continue;
      const int body = mask.type() == CV_16UC1 ? mask.at<uint16_t>(v, u) : mask.at<uint8_t>(v, u);
      const bool truly_moving = body != 0 && movers.count(body);
      const bool labelled_moving = f.body_id != 0;
      ++truth_votes[f.id][truly_moving ? body : 0];
      ++pred_votes[f.id][f.body_id];
      if (truly_moving) {
        per_body[body].first++;
        if (f.body_id > 0) per_body[body].second++;
      }
      // Score only after the movers present have had `settle` frames.
      bool settled = true;
      for (int b : movers) {
        auto it = first_moving_frame.find(b);
        if (it != first_moving_frame.end() && t.frame_seq < it->second + settle) settled = false;
      }
      if (!settled) continue;
      scored = true;
      tp += truly_moving && labelled_moving;
      fp += !truly_moving && labelled_moving;
      if (std::getenv("EVAL_DUMP_FN") && truly_moving && !labelled_moving) {
        std::printf("FN frame %lld id %lld uv %.0f %.0f body %d mask %d p %.3f epi %.2f fvb %.3f age %d\n",
                    static_cast<long long>(t.frame_seq), static_cast<long long>(f.id), f.u, f.v, f.body_id,
                    body, f.p_static, f.epipolar_px, f.fvb, f.age);
      }
      if (std::getenv("EVAL_DUMP_TP") && truly_moving && labelled_moving) {
        std::printf("TP frame %lld id %lld uv %.0f %.0f body %d mask %d p %.3f epi %.2f fvb %.3f age %d\n",
                    static_cast<long long>(t.frame_seq), static_cast<long long>(f.id), f.u, f.v, f.body_id,
                    body, f.p_static, f.epipolar_px, f.fvb, f.age);
      }
      if (std::getenv("EVAL_DUMP_FP") && !truly_moving && labelled_moving) {
        std::printf("FP frame %lld id %lld uv %.0f %.0f body %d mask %d p %.3f epi %.2f fvb %.3f age %d dist %.1f\n",
                    static_cast<long long>(t.frame_seq), static_cast<long long>(f.id), f.u, f.v, f.body_id,
                    body, f.p_static, f.epipolar_px, f.fvb, f.age, dist.at<float>(v, u));
      }
      if (std::getenv("EVAL_DUMP_TN") && !truly_moving && !labelled_moving) {
        std::printf("TN frame %lld id %lld uv %.0f %.0f body %d mask %d p %.3f epi %.2f fvb %.3f age %d\n",
                    static_cast<long long>(t.frame_seq), static_cast<long long>(f.id), f.u, f.v, f.body_id,
                    body, f.p_static, f.epipolar_px, f.fvb, f.age);
      }
      fn += truly_moving && !labelled_moving;
      tn += !truly_moving && !labelled_moving;
      const float to_silhouette = truly_moving ? dist_in.at<float>(v, u) : dist.at<float>(v, u);
      if (to_silhouette >= silhouette_px) {
        tp_off += truly_moving && labelled_moving;
        fp_off += !truly_moving && labelled_moving;
        fn_off += truly_moving && !labelled_moving;
      }
    }
    frames += scored;
    for (const auto& [body, counts] : per_body) {
      if (counts.first >= 3 && 2 * counts.second >= counts.first) detected_frame.try_emplace(body, t.frame_seq);
    }
  }
  // Track-level misclassification: each track's majority truth vs majority label.
  std::vector<int> truth, pred;
  for (const auto& [id, votes] : truth_votes) {
    auto majority = [](const std::map<int, int>& m) {
      int best = 0, count = -1;
      for (const auto& [k, c] : m) {
        if (c > count) {
          count = c;
          best = k;
        }
      }
      return best;
    };
    truth.push_back(majority(votes));
    pred.push_back(majority(pred_votes[id]));
  }
  const double recall = tp + fn > 0 ? static_cast<double>(tp) / (tp + fn) : 1.0;
  const double precision = tp + fp > 0 ? static_cast<double>(tp) / (tp + fp) : 1.0;
  const double recall_off = tp_off + fn_off > 0 ? static_cast<double>(tp_off) / (tp_off + fn_off) : 1.0;
  const double precision_off = tp_off + fp_off > 0 ? static_cast<double>(tp_off) / (tp_off + fp_off) : 1.0;
  const double miscl = Misclassification(truth, pred);
  std::printf("%s: frames scored %lld, moving features: recall %.3f precision %.3f (tp %lld fp %lld fn %lld)\n",
              name.c_str(), static_cast<long long>(frames), recall, precision,
              static_cast<long long>(tp), static_cast<long long>(fp), static_cast<long long>(fn));
  std::printf("  %.1f px or more from a mover's silhouette: recall %.3f precision %.3f (tp %lld fp %lld fn %lld)\n",
              silhouette_px, recall_off, precision_off, static_cast<long long>(tp_off),
              static_cast<long long>(fp_off), static_cast<long long>(fn_off));
  std::printf("track-level misclassification %.2f%% over %zu tracks\n", 100.0 * miscl, truth.size());
  std::string delays;
  double delay_sum = 0.0;
  int delay_n = 0;
  for (const auto& [body, first] : first_moving_frame) {
    auto it = detected_frame.find(body);
    const long long delay = it == detected_frame.end() ? -1 : static_cast<long long>(it->second - first);
    std::printf("  body %d: moving from frame %lld, detected %s\n", body, static_cast<long long>(first),
                delay < 0 ? "never" : ("after " + std::to_string(delay) + " frames").c_str());
    delays += (delays.empty() ? "" : ", ") + std::string("\"") + std::to_string(body) + "\": " + std::to_string(delay);
    if (delay >= 0) {
      delay_sum += static_cast<double>(delay);
      ++delay_n;
    }
  }
  const double false_moving = fp + tn > 0 ? static_cast<double>(fp) / static_cast<double>(fp + tn) : 0.0;
  std::printf("{\"name\": \"%s\", \"moving_recall\": %.4f, \"moving_precision\": %.4f, "
              "\"moving_recall_off_silhouette\": %.4f, \"moving_precision_off_silhouette\": %.4f, \"silhouette_px\": %.1f, "
              "\"misclassification\": %.4f, "
              "\"false_moving_fraction\": %.5f, \"frames_scored\": %lld, \"objects\": %zu, \"objects_detected\": %d, \"mean_detection_delay_frames\": %.2f, "
              "\"detection_delay_frames\": {%s}}\n",
              name.c_str(), recall, precision, recall_off, precision_off, silhouette_px, miscl, false_moving, static_cast<long long>(frames), first_moving_frame.size(),
              delay_n, delay_n ? delay_sum / delay_n : -1.0, delays.c_str());
  return 0;
}

}  // namespace
}  // namespace mbslam

int main(int argc, char** argv) { return mbslam::Run(argc, argv); }
