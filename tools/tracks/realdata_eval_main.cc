// mbslam-eval-realdata: scores the moving-feature labels of perception runs on real
// sequences with mask / class ground truth (../shared/data/README.md, "How it is scored").
//
//   mbslam-eval-realdata davis  --root DAVIS_ROOT --runs DIR [--sequences a,b] [--per-frame-dir DIR]
//       DIR/<sequence>/out.lcmlog is the lockstep output log of the run on <sequence>.
//       Per image: precision and recall of the features labelled moving (a feature inside
//       the mask is positive) and region IoU (J) of the moving region (union of the
//       objects' image hulls on PERCEPTION_OBJECTS; see realdata_scoring.h) with the mask.
//       Per sequence: means over images (undefined precision / recall excluded and counted);
//       overall: mean of the sequence means.
//   mbslam-eval-realdata camvid --root CAMVID_ROOT --run OUT.lcmlog
//       Where the moving-labelled features fall among CamVid's classes.
//   mbslam-eval-realdata static --run OUT.lcmlog [--name NAME]
//       A scene that does not move (TartanAir, TUM cabinet): the share of the features
//       labelled moving, of the images with any, and the objects (all phantoms).
//
// Prints a human summary and, last, one JSON line.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/lcm/channels.h"
#include "common/util/command_line.h"
#include "tools/eval/json.h"
#include "tools/eval/lcm_readers.h"
#include "tools/tracks/realdata_scoring.h"

namespace mbslam {
namespace {

namespace fs = std::filesystem;
using eval::Json;

// Diagnostics: the image with the truth outlined in blue, the predicted moving region in
// magenta, and the scored features: static green, moving red, unassigned yellow.
void WriteOverlay(const std::string& image_path, const cv::Mat& truth, const eval::PerceptionFrame* frame,
                  const std::string& out_path) {
  cv::Mat img = cv::imread(image_path, cv::IMREAD_COLOR);
  if (img.empty()) return;
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(truth.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  cv::drawContours(img, contours, -1, cv::Scalar(255, 128, 0), 2);
  if (frame != nullptr) {
    const cv::Mat region = eval::MovingRegion(*frame, truth.size());
    contours.clear();
    cv::findContours(region, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
    cv::drawContours(img, contours, -1, cv::Scalar(255, 0, 255), 2);
    for (size_t i = 0; i < frame->features.size(); ++i) {
      const int b = frame->body_ids[i];
      const cv::Scalar c = b > 0 ? cv::Scalar(0, 0, 255) : b == 0 ? cv::Scalar(0, 200, 0) : cv::Scalar(0, 255, 255);
      cv::circle(img, cv::Point(static_cast<int>(std::lround(frame->features[i].u)),
                                static_cast<int>(std::lround(frame->features[i].v))),
                 b > 0 ? 3 : 2, c, -1);
    }
  }
  cv::imwrite(out_path, img);
}

// Diagnostics: one CSV line per scored feature. `positive` marks the truth's positive
// pixels (DAVIS: the mask; CamVid: cars, pedestrians, cyclists): truth_dist_px is the
// feature's distance to the nearest one (0 on it).
void DumpFeatures(std::ofstream& out, const std::string& seq, const eval::PerceptionFrame& f, const cv::Mat& truth,
                  const cv::Mat& positive) {
  cv::Mat dist;
  if (cv::countNonZero(positive) > 0) cv::distanceTransform(positive == 0, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  for (const auto& t : f.tracks) {
    const int x = static_cast<int>(std::lround(t.u)), y = static_cast<int>(std::lround(t.v));
    const bool inside = x >= 0 && y >= 0 && x < truth.cols && y < truth.rows;
    const int label = inside ? truth.at<uint8_t>(y, x) : -1;
    const double d = inside && !dist.empty() ? dist.at<float>(y, x) : -1.0;
    out << seq << ',' << f.frame_seq << ',' << t.id << ',' << t.u << ',' << t.v << ',' << t.prev_u << ','
        << t.prev_v << ',' << t.body_id << ',' << label << ',' << t.p_static << ',' << t.epipolar_px << ','
        << t.fvb << ',' << t.age << ',' << static_cast<int>(t.flags) << ',' << d << '\n';
  }
}
constexpr const char* kDumpHeader =
    "sequence,frame,id,u,v,prev_u,prev_v,body_id,truth,p_static,epipolar_px,fvb,age,flags,truth_dist_px\n";

int Usage() {
  std::fprintf(stderr,
               "usage: mbslam-eval-realdata davis --root DAVIS_ROOT --runs DIR [--sequences a,b] [--per-frame-dir DIR]\n"
               "       mbslam-eval-realdata camvid --root CAMVID_ROOT --run OUT.lcmlog\n"
               "       mbslam-eval-realdata static --run OUT.lcmlog [--name NAME]   (a scene that does not move)\n"
               "diagnostics (both): [--dump FEATURES.csv] [--overlay-dir DIR [--overlay-every N]]\n");
  return 2;
}

// False (and the problem said) when an option is unknown or a number malformed.
bool OptionsOk(const CommandLineArgs& args) {
  const std::string problems = args.Problems();
  if (!problems.empty()) std::fprintf(stderr, "mbslam-eval-realdata: %s\n", problems.c_str());
  return problems.empty();
}

int Fail(const std::string& m) {
  std::fprintf(stderr, "mbslam-eval-realdata: %s\n", m.c_str());
  return 1;
}

Json Num(double v) { return std::isfinite(v) ? Json(v) : Json(); }

std::string Pct(double v) {
  if (!std::isfinite(v)) return "n/a";
  char b[32];
  std::snprintf(b, sizeof(b), "%.1f %%", 100.0 * v);
  return b;
}

// Frames of the camera pose log that were tracked (TRACKING_OK / RELOCALIZED), or -1.
int TrackedFrames(const std::string& log, const ChannelOptions& ch) {
  eval::CameraPoseLog poses;
  if (!eval::ReadCameraPoseLog(log, ch.perception_camera_pose, &poses).ok()) return -1;
  return static_cast<int>(poses.tracked.size());
}

int RunDavis(const CommandLineArgs& args) {
  const std::string root = args.Get("root"), runs = args.Get("runs"), per_frame_dir = args.Get("per-frame-dir");
  const std::string overlay_dir = args.Get("overlay-dir");
  const size_t overlay_every = static_cast<size_t>(std::max<int64_t>(1, args.GetInt("overlay-every", 1)));
  const std::string dump_path = args.Get("dump"), sequences = args.Get("sequences");
  if (!OptionsOk(args)) return Usage();
  if (root.empty() || runs.empty()) return Usage();
  std::ofstream dump;
  if (!dump_path.empty()) {
    dump.open(dump_path);
    dump << kDumpHeader;
  }
  std::set<std::string> wanted;
  {
    std::stringstream ss(sequences);
    std::string s;
    while (std::getline(ss, s, ',')) {
      if (!s.empty()) wanted.insert(s);
    }
  }
  std::vector<eval::DavisSequence> seqs;
  Status st = eval::ReadDavis(root, &seqs);
  if (!st.ok()) return Fail(st.message());
  const ChannelOptions ch;
  std::vector<eval::MaskSequenceScore> scores;
  std::vector<std::string> missing;
  Json per_seq = Json::Object();
  int undefined_p = 0, undefined_r = 0, frames = 0, no_output = 0;
  std::map<eval::RegionSource, int> sources;
  std::printf("%-15s %6s %7s %9s %7s %7s %7s %9s %9s %8s %7s\n", "sequence", "frames", "tracked",
              "feat/img", "moving", "P", "R", "J(IoU)", "P undef", "R undef", "pooledP");
  for (const eval::DavisSequence& seq : seqs) {
    if (!wanted.empty() && !wanted.count(seq.name)) continue;
    const std::string log = (fs::path(runs) / seq.name / "out.lcmlog").string();
    if (!fs::exists(log)) {
      missing.push_back(seq.name);
      continue;
    }
    std::map<int64_t, eval::PerceptionFrame> run;
    int bad = 0;
    st = eval::ReadPerceptionFrames(log, ch, &run, &bad);
    if (!st.ok()) return Fail(log + ": " + st.message());
    eval::MaskSequenceScore s;
    st = eval::ScoreDavisSequence(seq, run, &s);
    if (!st.ok()) return Fail(st.message());
    const int tracked = TrackedFrames(log, ch);
    if (dump.is_open() || !overlay_dir.empty()) {
      if (!overlay_dir.empty()) fs::create_directories(fs::path(overlay_dir) / seq.name);
      for (size_t i = 0; i < seq.masks.size(); ++i) {
        cv::Mat mask;
        if (!eval::LoadBinaryMask(seq.masks[i], &mask).ok()) continue;
        auto it = run.find(static_cast<int64_t>(i));
        const eval::PerceptionFrame* f = it == run.end() ? nullptr : &it->second;
        if (dump.is_open() && f) DumpFeatures(dump, seq.name, *f, mask, mask);
        if (!overlay_dir.empty() && i % overlay_every == 0) {
          char name[32];
          std::snprintf(name, sizeof(name), "%05zu.png", i);
          WriteOverlay(seq.images[i], mask, f, (fs::path(overlay_dir) / seq.name / name).string());
        }
      }
    }
    int feats = 0, moving = 0, in_mask = 0;
    for (const auto& f : s.per_frame) {
      feats += f.num_features;
      moving += f.num_moving;
      in_mask += f.counts.true_positives + f.counts.false_negatives;
    }
    const double feat_per_img = s.frames ? static_cast<double>(feats) / s.frames : 0.0;
    const double moving_frac = feats ? static_cast<double>(moving) / feats : 0.0;
    const double mask_frac = feats ? static_cast<double>(in_mask) / feats : 0.0;
    std::printf("%-15s %6d %7d %9.0f %7s %7s %7s %9s %9d %8d %7s\n", seq.name.c_str(), s.frames, tracked,
                feat_per_img, Pct(moving_frac).c_str(), Pct(s.mean_precision).c_str(),
                Pct(s.mean_recall).c_str(), Pct(s.mean_iou).c_str(), s.frames_precision_undefined,
                s.frames_recall_undefined, Pct(s.pooled.precision).c_str());
    Json j = Json::Object();
    j.Set("precision", Num(s.mean_precision)).Set("recall", Num(s.mean_recall)).Set("iou", Num(s.mean_iou));
    j.Set("iou_ceiling_truth_hull", Num(s.mean_hull_iou_ceiling));
    j.Set("pooled_precision", Num(s.pooled.true_positives + s.pooled.false_positives > 0 ? s.pooled.precision : NAN));
    j.Set("pooled_recall", Num(s.pooled.true_positives + s.pooled.false_negatives > 0 ? s.pooled.recall : NAN));
    j.Set("frames", s.frames).Set("frames_without_output", s.frames_without_output);
    j.Set("frames_precision_undefined", s.frames_precision_undefined);
    j.Set("frames_recall_undefined", s.frames_recall_undefined);
    j.Set("tracked_frames", tracked).Set("features_per_frame", feat_per_img);
    j.Set("moving_feature_fraction", moving_frac).Set("mask_feature_fraction", mask_frac);
    j.Set("unassigned_features", s.unassigned).Set("undecodable_messages", bad);
    j.Set("pooled_precision_with_unassigned", Num(s.pooled_with_unassigned.precision));
    j.Set("pooled_recall_with_unassigned", Num(s.pooled_with_unassigned.recall));
    j.Set("false_positives", s.pooled.false_positives).Set("false_positives_near_mask", s.fp_near_mask);
    Json src = Json::Object();
    for (const auto& [k, n] : s.region_sources) {
      src.Set(eval::RegionSourceName(k), n);
      sources[k] += n;
    }
    j.Set("region_sources", src);
    per_seq.Set(seq.name, j);
    undefined_p += s.frames_precision_undefined;
    undefined_r += s.frames_recall_undefined;
    frames += s.frames;
    no_output += s.frames_without_output;
    if (!per_frame_dir.empty()) {
      fs::create_directories(per_frame_dir);
      std::ofstream out(fs::path(per_frame_dir) / (seq.name + ".csv"));
      out << "frame,has_output,features,moving,tp,fp,fn,tn,precision,recall,iou,region_source\n";
      for (const auto& f : s.per_frame) {
        out << f.frame_seq << ',' << f.has_output << ',' << f.num_features << ',' << f.num_moving << ','
            << f.counts.true_positives << ',' << f.counts.false_positives << ','
            << f.counts.false_negatives << ',' << f.counts.true_negatives << ','
            << (std::isnan(f.precision) ? "" : std::to_string(f.precision)) << ','
            << (std::isnan(f.recall) ? "" : std::to_string(f.recall)) << ',' << f.iou << ','
            << eval::RegionSourceName(f.region_source) << '\n';
      }
    }
    scores.push_back(std::move(s));
  }
  if (scores.empty()) return Fail("no run logs found under " + runs);
  const eval::MaskDatasetScore d = eval::SummarizeMaskDataset(scores);
  std::printf("mean over %d sequences: precision %s, recall %s, J (IoU) %s; pooled precision %s, recall %s\n",
              d.sequences, Pct(d.mean_precision).c_str(), Pct(d.mean_recall).c_str(), Pct(d.mean_iou).c_str(),
              Pct(d.pooled.precision).c_str(), Pct(d.pooled.recall).c_str());
  double ceiling = 0.0;
  for (const auto& sc : scores) ceiling += sc.mean_hull_iou_ceiling / static_cast<double>(scores.size());
  std::printf("J of the truth's own convex hull (ceiling for a hull-shaped region): mean %s\n", Pct(ceiling).c_str());
  std::printf("with unassigned tracks (body -1) counted as moving: pooled precision %s, recall %s\n",
              Pct(d.pooled_with_unassigned.precision).c_str(), Pct(d.pooled_with_unassigned.recall).c_str());
  std::printf("%d of %d images had no moving-labelled feature (precision undefined, excluded from its mean); "
              "%d had no scored feature inside the mask (recall undefined, excluded); %d had no output\n",
              undefined_p, frames, undefined_r, no_output);
  std::printf("moving region: union of the objects' image hulls (PERCEPTION_OBJECTS); images by source:");
  for (const auto& [k, n] : sources) std::printf(" %s %d", eval::RegionSourceName(k), n);
  std::printf("\n");
  if (!missing.empty()) {
    std::printf("no run for:");
    for (const auto& m : missing) std::printf(" %s", m.c_str());
    std::printf("\n");
  }
  Json j = Json::Object();
  j.Set("dataset", "davis2016").Set("sequences", static_cast<int>(scores.size()));
  j.Set("mean_precision", Num(d.mean_precision)).Set("mean_recall", Num(d.mean_recall)).Set("mean_iou", Num(d.mean_iou));
  j.Set("pooled_precision", Num(d.pooled.precision)).Set("pooled_recall", Num(d.pooled.recall));
  j.Set("pooled_precision_with_unassigned", Num(d.pooled_with_unassigned.precision));
  j.Set("pooled_recall_with_unassigned", Num(d.pooled_with_unassigned.recall));
  j.Set("mean_iou_ceiling_truth_hull", Num(ceiling));
  j.Set("frames", frames).Set("frames_precision_undefined", undefined_p).Set("frames_recall_undefined", undefined_r);
  j.Set("frames_without_output", no_output);
  j.Set("precision_rule", "per image TP/(TP+FP) over features labelled moving (body_id > 0); images without any are excluded and counted");
  j.Set("region", "union of PERCEPTION_OBJECTS image hulls (tracks_t hulls, then moving-feature hulls, only where no objects_t)");
  Json src = Json::Object();
  for (const auto& [k, n] : sources) src.Set(eval::RegionSourceName(k), n);
  j.Set("region_sources", src);
  Json miss = Json::Array();
  for (const auto& m : missing) miss.Push(m);
  j.Set("missing_runs", miss).Set("per_sequence", per_seq);
  std::printf("%s\n", j.Dump().c_str());
  return 0;
}

int RunCamVid(const CommandLineArgs& args) {
  const std::string root = args.Get("root"), log = args.Get("run");
  const size_t every = static_cast<size_t>(std::max<int64_t>(1, args.GetInt("overlay-every", 1)));
  const std::string dump_path = args.Get("dump"), overlay_dir = args.Get("overlay-dir");
  if (!OptionsOk(args)) return Usage();
  if (root.empty() || log.empty()) return Usage();
  std::vector<eval::CamVidFrame> frames;
  Status st = eval::ReadCamVid(root, &frames);
  if (!st.ok()) return Fail(st.message());
  const ChannelOptions ch;
  std::map<int64_t, eval::PerceptionFrame> run;
  int bad = 0;
  st = eval::ReadPerceptionFrames(log, ch, &run, &bad);
  if (!st.ok()) return Fail(log + ": " + st.message());
  eval::CamVidRunScore s;
  st = eval::ScoreCamVid(frames, run, &s);
  if (!st.ok()) return Fail(st.message());
  const int tracked = TrackedFrames(log, ch);
  if (!dump_path.empty() || !overlay_dir.empty()) {
    std::ofstream dump;
    if (!dump_path.empty()) {
      dump.open(dump_path);
      dump << kDumpHeader;
    }
    if (!overlay_dir.empty()) fs::create_directories(overlay_dir);
    for (size_t i = 0; i < frames.size(); ++i) {
      const cv::Mat labels = cv::imread(frames[i].label, cv::IMREAD_GRAYSCALE);
      if (labels.empty()) continue;
      auto it = run.find(static_cast<int64_t>(i));
      const eval::PerceptionFrame* f = it == run.end() ? nullptr : &it->second;
      cv::Mat movable(labels.size(), CV_8UC1, cv::Scalar(0));
      for (int y = 0; y < labels.rows; ++y) {
        for (int x = 0; x < labels.cols; ++x) {
          if (eval::IsCamVidMovableClass(labels.at<uint8_t>(y, x))) movable.at<uint8_t>(y, x) = 255;
        }
      }
      if (dump.is_open() && f) DumpFeatures(dump, "camvid", *f, labels, movable);
      if (!overlay_dir.empty() && i % every == 0) {
        char name[32];
        std::snprintf(name, sizeof(name), "%05zu.png", i);
        WriteOverlay(frames[i].image, movable, f, (fs::path(overlay_dir) / name).string());
      }
    }
  }
  static const char* kNames[] = {"sky", "building", "pole", "road", "pavement", "tree",
                                 "sign", "fence", "car", "pedestrian", "bicyclist", "void"};
  auto name = [](int c) { return c >= 0 && c <= 11 ? std::string(kNames[c]) : "label" + std::to_string(c); };
  std::printf("CamVid: %d labelled images scored (%d without output, %d tracked), %d scored features, %d labelled moving\n",
              s.frames, s.frames_without_output, tracked, s.features, s.moving.moving);
  std::printf("moving-labelled features on static classes: %s (%d), on cars / pedestrians / cyclists: %s (%d), on void: %d\n",
              Pct(s.moving_on_static).c_str(), s.moving.on_static, Pct(s.moving_on_movable).c_str(),
              s.moving.on_movable, s.moving.on_void);
  std::printf("features on cars / pedestrians / cyclists labelled moving: %s of %d (recall proxy; parked cars are static)\n",
              Pct(s.movable_labelled_moving).c_str(), s.on_movable);
  std::printf("features on static classes labelled moving: %s of %d\n", Pct(s.static_labelled_moving).c_str(), s.on_static);
  std::printf("with unassigned tracks (body -1) counted as moving: %s of %d on static classes\n",
              Pct(s.non_static_on_static).c_str(), s.non_static.moving);
  const double far_share = s.moving.moving > 0
      ? static_cast<double>(s.moving.on_static - s.moving_on_static_near_movable) / s.moving.moving : NAN;
  std::printf("diagnostic: %d of the %d on static classes lie within %.0f px of a car / pedestrian / cyclist pixel "
              "(coarse labels, bicycle wheels, shadows); farther ones are %s of the moving-labelled features\n",
              s.moving_on_static_near_movable, s.moving.on_static, eval::kNearTruthPx, Pct(far_share).c_str());
  std::printf("per class (features, labelled moving):");
  Json per_class = Json::Object();
  for (const auto& [c, n] : s.per_class) {
    auto it = s.moving_per_class.find(c);
    const int m = it == s.moving_per_class.end() ? 0 : it->second;
    std::printf(" %s %d/%d", name(c).c_str(), n, m);
    per_class.Set(name(c), Json::Object().Set("features", n).Set("moving", m));
  }
  std::printf("\n");
  Json j = Json::Object();
  j.Set("dataset", "camvid_0016E5_15hz");
  j.Set("moving_on_static_classes", s.moving.moving > 0 ? Json(s.moving_on_static) : Json());
  j.Set("moving_on_movable_classes", s.moving.moving > 0 ? Json(s.moving_on_movable) : Json());
  j.Set("movable_features_labelled_moving", s.on_movable > 0 ? Json(s.movable_labelled_moving) : Json());
  j.Set("static_features_labelled_moving", s.on_static > 0 ? Json(s.static_labelled_moving) : Json());
  j.Set("moving_features", s.moving.moving).Set("moving_on_static", s.moving.on_static);
  j.Set("moving_on_movable", s.moving.on_movable).Set("moving_on_void", s.moving.on_void);
  j.Set("features", s.features).Set("features_on_movable", s.on_movable).Set("features_on_static", s.on_static);
  j.Set("unassigned_features", s.unassigned);
  j.Set("non_static_on_static_classes", s.non_static.moving > 0 ? Json(s.non_static_on_static) : Json());
  j.Set("moving_on_static_near_movable", s.moving_on_static_near_movable).Set("near_px", eval::kNearTruthPx);
  j.Set("moving_on_static_classes_far_from_movable", Num(far_share));
  j.Set("frames", s.frames).Set("frames_without_output", s.frames_without_output).Set("tracked_frames", tracked);
  j.Set("undecodable_messages", bad).Set("per_class", per_class);
  std::printf("%s\n", j.Dump().c_str());
  return 0;
}

// A scene whose world does not move: every moving label is false, every object a phantom.
int RunStatic(const CommandLineArgs& args) {
  const std::string log = args.Get("run"), name = args.Get("name", "static");
  if (!OptionsOk(args)) return Usage();
  if (log.empty()) return Usage();
  const ChannelOptions ch;
  std::map<int64_t, eval::PerceptionFrame> run;
  int bad = 0;
  const Status st = eval::ReadPerceptionFrames(log, ch, &run, &bad);
  if (!st.ok()) return Fail(log + ": " + st.message());
  const eval::StaticSceneScore s = eval::ScoreStaticScene(run);
  if (s.frames == 0) return Fail(log + ": no PERCEPTION_TRACKS");
  std::printf("%s (static scene): %d images, %d scored features, %d labelled moving (%s), in %d images (%s), "
              "%zu phantom objects, %d unassigned\n",
              name.c_str(), s.frames, s.features, s.moving, Pct(s.false_moving).c_str(), s.frames_with_moving,
              Pct(s.frames_with_moving_share).c_str(), s.objects.size(), s.unassigned);
  Json j = Json::Object();
  j.Set("dataset", name).Set("static_false_moving_fraction", s.false_moving);
  j.Set("static_frames_with_moving_share", s.frames_with_moving_share);
  j.Set("static_phantom_objects", static_cast<int>(s.objects.size()));
  j.Set("moving_features", s.moving).Set("features", s.features).Set("unassigned_features", s.unassigned);
  j.Set("frames", s.frames).Set("undecodable_messages", bad);
  std::printf("%s\n", j.Dump().c_str());
  return 0;
}

int Run(int argc, char** argv) {
  if (argc < 2) return Usage();
  const std::string cmd = argv[1];
  const CommandLineArgs args(argc, argv, 2);
  if (cmd == "davis") return RunDavis(args);
  if (cmd == "camvid") return RunCamVid(args);
  if (cmd == "static") return RunStatic(args);
  return Usage();
}

}  // namespace
}  // namespace mbslam

int main(int argc, char** argv) { return mbslam::Run(argc, argv); }
