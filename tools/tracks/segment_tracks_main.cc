// mbslam-segment-tracks: the tracks-only entry point of the segmentation, scored on a
// folder of *.tracks.txt files (Hopkins 155 layout) in two settings:
//   known_k  the number of motions is given (multi-view subspace clustering, the
//            multibody initialisation of the pipeline run on the whole sequence);
//   online   nothing is given: the incremental segmenter runs frame by frame on the
//            tracks (as it does live), with its multibody initialisation estimating the
//            number of motions; the labels after the last frame are scored.
// Misclassification = fraction of tracks wrong under the best one-to-one matching of
// predicted to true groups (Hungarian). Prints per-sequence lines, a summary and, last,
// one JSON line.
//
//   mbslam-segment-tracks --root DIR [--mode known_k|online|both] [--exclude NAME ...]
//                         [--only NAME] [--focal-factor F] [--order silhouette|cut|merge|eigengap]
//                         [--hold 0|1] [--multibody-every FRAMES (5)]
//                         [--multibody-max-tracks N (400)] [--multibody-max-frames N (30)] ...

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <dirent.h>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/util/command_line.h"
#include "common/util/statistics.h"
#include "services/perception/segmentation/motion_segmenter.h"
#include "services/perception/segmentation/subspace_clustering.h"
#include "services/perception/segmentation/tracks_file.h"
#include "tools/tracks/misclassification.h"

namespace mbslam {
namespace {

std::vector<int> OnlineLabels(const TrackSet& t, double focal_factor, const SegmentationOptions& options) {
  MotionSegmenter seg(options);
  const double f = focal_factor * t.width;
  const double cx = (t.width - 1) * 0.5, cy = (t.height - 1) * 0.5;
  std::vector<int> labels(static_cast<size_t>(t.num_tracks()), -1);
  for (int frame = 0; frame < t.frames; ++frame) {
    SegmenterInput in;
    in.frame_index = frame;
    in.width = t.width;
    in.height = t.height;
    in.focal_px = f;
    in.K << f, 0, cx, 0, f, cy, 0, 0, 1;
    for (int p = 0; p < t.num_tracks(); ++p) {
      const Eigen::Vector2d& uv = t.positions[static_cast<size_t>(p)][static_cast<size_t>(frame)];
      if (!uv.allFinite()) continue;
      TrackObservation o;
      o.id = p;
      o.uv = uv;
      o.xy = Eigen::Vector2d((uv.x() - cx) / f, (uv.y() - cy) / f);
      in.observations.push_back(o);
    }
    const SegmentationResult r = seg.Update(in);
    if (frame == t.frames - 1) {
      for (const TrackLabel& l : r.labels) labels[static_cast<size_t>(l.id)] = l.body_id;
    }
  }
  return labels;
}

double Mean(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

int Run(int argc, char** argv) {
  std::string root, mode = "both", only;
  std::set<std::string> exclude = {"dancing"};
  double focal_factor = 1.0;
  SubspaceClusteringOptions sc_options;
  SegmentationOptions seg_defaults;
  double mb_evidence = seg_defaults.multibody_evidence;
  bool keep_objects = seg_defaults.multibody_keep_objects;
  bool hold = seg_defaults.multibody_hold;
  int max_frames = seg_defaults.multibody_max_frames;
  int max_tracks = 400;  // tracks clustered per initialisation (the service default is 250)
  int every = 5;  // re-initialise often: the labels reported are those of the last grouping (multibody_hold)
  double heading_keep_ratio = seg_defaults.two_view.heading_keep_ratio;
  const CommandLineArgs args(argc, argv);
  root = args.Get("root");
  mode = args.Get("mode", mode);
  for (const std::string& name : args.GetAll("exclude")) exclude.insert(name);
  only = args.Get("only");
  focal_factor = args.GetDouble("focal-factor", focal_factor);
  sc_options.alpha = args.GetDouble("ssc-alpha", sc_options.alpha);
  sc_options.projection_dims_per_motion =
      static_cast<int>(args.GetInt("ssc-projection", sc_options.projection_dims_per_motion));
  if (args.Has("ssc-mass")) sc_options.coefficient_masses = {args.GetDouble("ssc-mass", 0.0)};
  sc_options.method = args.Get("method", sc_options.method);
  sc_options.lsr_lambda = args.GetDouble("lsr-lambda", sc_options.lsr_lambda);
  sc_options.merge_ratio = args.GetDouble("merge-ratio", sc_options.merge_ratio);
  sc_options.order_cut_weight = args.GetDouble("cut-weight", sc_options.order_cut_weight);
  mb_evidence = args.GetDouble("multibody-evidence", mb_evidence);
  keep_objects = args.GetInt("keep-objects", keep_objects ? 1 : 0) != 0;
  hold = args.GetInt("hold", hold ? 1 : 0) != 0;
  every = static_cast<int>(args.GetInt("multibody-every", every));
  max_frames = static_cast<int>(args.GetInt("multibody-max-frames", max_frames));
  max_tracks = static_cast<int>(args.GetInt("multibody-max-tracks", max_tracks));
  sc_options.order_selection = args.Get("order", sc_options.order_selection);
  sc_options.silhouette_cut_weight = args.GetDouble("silhouette-cut", sc_options.silhouette_cut_weight);
  sc_options.silhouette_residual_weight = args.GetDouble("silhouette-residual", sc_options.silhouette_residual_weight);
  sc_options.min_silhouette = args.GetDouble("min-silhouette", sc_options.min_silhouette);
  sc_options.max_motions = static_cast<int>(args.GetInt("max-motions", sc_options.max_motions));
  sc_options.refine_iterations = static_cast<int>(args.GetInt("refine", sc_options.refine_iterations));
  sc_options.subspace_dimension = static_cast<int>(args.GetInt("subspace-dim", sc_options.subspace_dimension));
  heading_keep_ratio = args.GetDouble("heading-keep-ratio", heading_keep_ratio);
  if (const std::string problems = args.Problems(); !problems.empty()) {
    std::fprintf(stderr, "mbslam-segment-tracks: %s\nusage: mbslam-segment-tracks --root DIR [--mode known_k|online|both] [--exclude NAME] [--only NAME]\n",
                 problems.c_str());
    return 2;
  }
  if (root.empty() || (mode != "known_k" && mode != "online" && mode != "both")) {
    std::fprintf(stderr, "mbslam-segment-tracks: --root DIR is required; --mode known_k|online|both\n");
    return 2;
  }
  std::vector<std::string> files;
  DIR* dir = opendir(root.c_str());
  if (!dir) {
    std::fprintf(stderr, "mbslam-segment-tracks: cannot open %s\n", root.c_str());
    return 1;
  }
  while (dirent* e = readdir(dir)) {
    const std::string name = e->d_name;
    const std::string suffix = ".tracks.txt";
    if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      const std::string base = name.substr(0, name.size() - suffix.size());
      if (exclude.count(base) || (!only.empty() && base != only)) continue;
      files.push_back(root + "/" + name);
    }
  }
  closedir(dir);
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    std::fprintf(stderr, "mbslam-segment-tracks: no *.tracks.txt in %s\n", root.c_str());
    return 1;
  }

  // Short near-affine track sequences: the multi-view multibody initialisation applies.
  SegmentationOptions seg_options;
  seg_options.multibody_init = true;
  seg_options.multibody = sc_options;  // the clustering flags apply to both settings
  seg_options.multibody_evidence = mb_evidence;
  seg_options.multibody_keep_objects = keep_objects;
  seg_options.multibody_hold = hold;
  seg_options.multibody_every_frames = every;
  seg_options.multibody_max_frames = max_frames;
  seg_options.multibody_max_tracks = max_tracks;
  seg_options.two_view.heading_keep_ratio = heading_keep_ratio;
  const bool do_known = mode != "online", do_online = mode != "known_k";
  std::map<std::string, std::vector<double>> known, online;  // "2", "3", "all"
  int online_k_right = 0, sequences = 0;
  double seconds_known = 0.0, seconds_online = 0.0;
  for (const std::string& path : files) {
    TrackSet t;
    const Status s = ReadTrackSet(path, &t);
    if (!s.ok()) {
      std::fprintf(stderr, "skipping: %s\n", s.message().c_str());
      continue;
    }
    ++sequences;
    const int k = t.num_groups();
    const std::string group = k == 2 ? "2" : (k == 3 ? "3" : "other");
    std::printf("%-24s P=%3d F=%3d k=%d", t.name.c_str(), t.num_tracks(), t.frames, k);
    if (do_known) {
      std::vector<int> used;
      const Eigen::MatrixXd Y = t.CompleteTrajectoryMatrix(&used);
      const auto t0 = std::chrono::steady_clock::now();
      const std::vector<int> pred_used = ClusterTrajectories(Y, k, sc_options);
      seconds_known += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::vector<int> pred(static_cast<size_t>(t.num_tracks()), -1);
      for (size_t c = 0; c < used.size(); ++c) pred[static_cast<size_t>(used[c])] = pred_used[c];
      const double err = Misclassification(t.labels, pred);
      known[group].push_back(err);
      known["all"].push_back(err);
      std::printf("  known_k %6.2f%%", 100.0 * err);
    }
    if (do_online) {
      const auto t0 = std::chrono::steady_clock::now();
      const std::vector<int> pred = OnlineLabels(t, focal_factor, seg_options);
      seconds_online += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double err = Misclassification(t.labels, pred);
      online[group].push_back(err);
      online["all"].push_back(err);
      const int found = static_cast<int>(std::set<int>(pred.begin(), pred.end()).size());
      online_k_right += found == k;
      std::printf("  online %6.2f%% (groups %d)", 100.0 * err, found);
    }
    std::printf("\n");
    std::fflush(stdout);
  }

  std::printf("\nsequences: %d\n", sequences);
  auto report = [](const char* name, std::map<std::string, std::vector<double>>& m) {
    for (const char* g : {"2", "3", "all"}) {
      std::printf("%-8s %-4s motions: mean %6.2f%%  median %6.2f%%  (n=%zu)\n", name, g,
                  100.0 * Mean(m[g]), 100.0 * MedianOfReport(m[g]), m[g].size());
    }
  };
  if (do_known) report("known_k", known);
  if (do_online) report("online", online);

  std::string json = "{\"sequences\": " + std::to_string(sequences);
  auto add = [&json](const std::string& key, double v) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.6f", v);
    json += ", \"" + key + "\": " + buf;
  };
  if (do_known) {
    add("mean_2_known_k", Mean(known["2"]));
    add("median_2_known_k", MedianOfReport(known["2"]));
    add("mean_3_known_k", Mean(known["3"]));
    add("median_3_known_k", MedianOfReport(known["3"]));
    add("mean_all_known_k", Mean(known["all"]));
    add("median_all_known_k", MedianOfReport(known["all"]));
    add("seconds_known_k", seconds_known);
  }
  if (do_online) {
    add("mean_2_online", Mean(online["2"]));
    add("median_2_online", MedianOfReport(online["2"]));
    add("mean_3_online", Mean(online["3"]));
    add("median_3_online", MedianOfReport(online["3"]));
    add("mean_all_online", Mean(online["all"]));
    add("median_all_online", MedianOfReport(online["all"]));
    add("online_group_count_correct", sequences ? static_cast<double>(online_k_right) / sequences : 0.0);
    add("seconds_online", seconds_online);
  }
  json += "}";
  std::printf("%s\n", json.c_str());
  return 0;
}

}  // namespace
}  // namespace mbslam

int main(int argc, char** argv) { return mbslam::Run(argc, argv); }
