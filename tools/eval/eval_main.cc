// mbslam-eval: the evaluation toolkit on the command line. Every subcommand prints a
// human summary and, as its last line, one JSON object.
//
//   mbslam-eval ate --est est.tum --gt gt.tum [--align sim3|se3|none] [--plot out.png]
//   mbslam-eval ate --est-log run.lcmlog --gt-log seq.lcmlog
//   mbslam-eval seg --pred labels.txt --truth seq.tracks.txt
//   mbslam-eval seg --pred-dir predictions/ --tracks-dir ../shared/data/hopkins155
//   mbslam-eval masks --pred-dir masks/ --gt-dir ../shared/data/davis2016/Annotations/camel
//   mbslam-eval camvid --features moving_features.txt
//   mbslam-eval objects --est-log run.lcmlog --gt-log seq.lcmlog
//   mbslam-eval perturb --in gt.tum --out est.tum --scale 2 --rot-deg 30 --noise 0.05
//   mbslam-eval perturb-labels --truth seq.tracks.txt --out pred.txt --wrong 5
//   mbslam-eval datasets

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "common/lcm/channels.h"
#include "common/util/atomic_file.h"
#include "common/util/command_line.h"
#include "common/util/statistics.h"
#include "tools/eval/camera_metrics.h"
#include "tools/eval/datasets.h"
#include "tools/eval/json.h"
#include "tools/eval/lcm_readers.h"
#include "tools/eval/object_metrics.h"
#include "tools/eval/perturb.h"
#include "tools/eval/plot.h"
#include "tools/eval/point_metrics.h"
#include "tools/eval/reconstruction_metrics.h"
#include "tools/eval/segmentation_metrics.h"

namespace {

using mbslam::Status;
namespace eval = mbslam::eval;
namespace fs = std::filesystem;
using eval::Json;

int Fail(const std::string& message) {
  std::cerr << "mbslam-eval: " << message << "\n";
  return 1;
}

int Finish(const Json& json, const mbslam::CommandLineArgs& args) {
  const bool write_json = args.Has("json");
  const std::string problems = args.Problems();
  if (!problems.empty()) {
    return Fail(problems);
  }
  const std::string text = json.Dump();
  if (write_json) {
    const Status st = mbslam::WriteStringAtomically(args.Get("json"), text + "\n");
    if (!st.ok()) {
      return Fail(st.message());
    }
  }
  std::cout << text << std::endl;
  return 0;
}

Json StatsJson(const eval::ErrorStats& s) {
  Json j = Json::Object();
  j.Set("rmse", s.rmse)
      .Set("mean", s.mean)
      .Set("median", s.median)
      .Set("std", s.std)
      .Set("min", s.min);
  j.Set("max", s.max).Set("count", s.count);
  return j;
}

bool ParseVector3(const std::string& text, Eigen::Vector3d* v) {
  return std::sscanf(text.c_str(), "%lf,%lf,%lf", &v->x(), &v->y(), &v->z()) == 3;
}

// ---------------------------------------------------------------- ate

// The camera's ground truth from --PREFIX FILE.tum, --PREFIX-log LOG, --PREFIX-sequence DIR
// or --PREFIX-tartanair pose_left.txt (prefix "gt"; "align-gt" for --align-est's run).
Status LoadGroundTruthCamera(const mbslam::CommandLineArgs& args,
                             const mbslam::ChannelOptions& channels, eval::Trajectory* gt,
                             std::string* description, const std::string& prefix = "gt") {
  if (args.Has(prefix)) {
    *description = args.Get(prefix);
    return eval::ReadTumTrajectory(args.Get(prefix), gt);
  }
  if (args.Has(prefix + "-log")) {
    eval::GroundTruthLog log;
    MBSLAM_RETURN_IF_ERROR(eval::ReadGroundTruthLog(
        args.Get(prefix + "-log"), args.Get("gt-channel", channels.ground_truth), &log));
    *gt = log.camera;
    *description = args.Get(prefix + "-log") + " (" + log.source + ")";
    return Status::Ok();
  }
  if (args.Has(prefix + "-sequence")) {
    eval::SequenceFolder seq;
    MBSLAM_RETURN_IF_ERROR(eval::ReadSequenceFolder(args.Get(prefix + "-sequence"), &seq));
    *gt = seq.camera;
    *description = args.Get(prefix + "-sequence");
    return Status::Ok();
  }
  if (args.Has(prefix + "-tartanair")) {
    *description = args.Get(prefix + "-tartanair");
    const int64_t frame_period_us = args.GetInt("frame-period-us", 1000000);
    if (const std::string problems = args.ParseProblems(); !problems.empty()) return Status::Error(problems);
    return eval::ReadTartanAirPoses(args.Get(prefix + "-tartanair"), frame_period_us, gt);
  }
  return Status::Error("ate: give --" + prefix + " FILE.tum, --" + prefix + "-log LOG, --" +
                       prefix + "-sequence DIR or --" + prefix + "-tartanair pose_left.txt");
}

int RunAte(const mbslam::CommandLineArgs& args) {
  const mbslam::ChannelOptions channels;
  eval::AteOptions options;
  options.alignment = args.Get("align", "sim3");
  options.max_time_diff_us = args.GetInt("max-dt-us", options.max_time_diff_us);
  eval::RpeOptions rpe_options;
  rpe_options.delta_frames = static_cast<int>(args.GetInt("rpe-delta", 1));
  rpe_options.delta_us = args.GetInt("rpe-delta-us", 0);
  if (const std::string problems = args.ParseProblems(); !problems.empty()) return Fail(problems);
  eval::Trajectory est, gt;
  std::string gt_description, est_description;
  int est_messages = -1, est_metric = 0;
  Status st = LoadGroundTruthCamera(args, channels, &gt, &gt_description);
  if (!st.ok()) {
    return Fail(st.message());
  }
  if (args.Has("est")) {
    est_description = args.Get("est");
    st = eval::ReadTumTrajectory(args.Get("est"), &est);
  } else if (args.Has("est-log")) {
    eval::CameraPoseLog log;
    est_description = args.Get("est-log");
    st = eval::ReadCameraPoseLog(args.Get("est-log"),
                                 args.Get("est-channel", channels.perception_camera_pose), &log);
    est = log.tracked;
    est_messages = log.num_messages;
    est_metric = log.num_metric;
  } else {
    st = Status::Error("ate: give --est FILE.tum or --est-log LOG");
  }
  if (!st.ok()) {
    return Fail(st.message());
  }

  // --align-est OTHER.tum with its truth (--align-gt-log LOG, --align-gt F.tum, ...): the alignment
  // is computed on another run (its estimate against its truth) and applied to --est as it is: a
  // run that relocalised in a map the other run made is scored in that map's frame.
  std::string alignment_label = options.alignment;
  if (args.Has("align-est")) {
    eval::Trajectory other_est, other_gt;
    st = eval::ReadTumTrajectory(args.Get("align-est"), &other_est);
    std::string other_description;
    if (st.ok())
      st = LoadGroundTruthCamera(args, channels, &other_gt, &other_description, "align-gt");
    eval::AteResult other;
    if (st.ok()) st = eval::ComputeAte(other_est, other_gt, options, &other);
    if (!st.ok()) return Fail("ate: alignment from " + args.Get("align-est") + ": " + st.message());
    options.fixed_gt_from_est = other.gt_from_est;
    alignment_label = "from " + args.Get("align-est");
    std::printf("alignment from %s: %zu pairs, ATE there %.6f m\n", args.Get("align-est").c_str(),
                other.pairs.size(), other.translation.rmse);
  }
  eval::AteResult ate;
  st = eval::ComputeAte(est, gt, options, &ate);
  if (!st.ok()) {
    return Fail(st.message());
  }
  rpe_options.est_scale = ate.gt_from_est.scale;
  eval::RpeResult rpe;
  const Status rpe_status = eval::ComputeRpe(est, gt, ate.pairs, rpe_options, &rpe);
  const double tracked = eval::FractionTracked(est, gt, options.max_time_diff_us);

  std::printf("ATE of %s against %s\n", est_description.c_str(), gt_description.c_str());
  std::printf(
      "  poses: %d estimated, %d ground truth, %zu associated (max dt %lld us), fraction tracked "
      "%.3f\n",
      ate.num_est, ate.num_gt, ate.pairs.size(), static_cast<long long>(options.max_time_diff_us),
      tracked);
  std::printf("  alignment %s: scale %.6f\n", alignment_label.c_str(), ate.gt_from_est.scale);
  std::printf("  ATE translation: rmse %.6f m, mean %.6f, median %.6f, max %.6f\n",
              ate.translation.rmse, ate.translation.mean, ate.translation.median,
              ate.translation.max);
  std::printf("  ATE rotation: rmse %.4f deg\n", ate.rotation_deg.rmse);
  if (rpe_status.ok()) {
    std::printf("  RPE (delta %s): translation rmse %.6f m, rotation rmse %.4f deg (%d pairs)\n",
                rpe_options.delta_us > 0
                    ? (std::to_string(rpe_options.delta_us) + " us").c_str()
                    : (std::to_string(rpe_options.delta_frames) + " frames").c_str(),
                rpe.translation.rmse, rpe.rotation_deg.rmse, rpe.translation.count);
  } else {
    std::printf("  RPE: %s\n", rpe_status.message().c_str());
  }
  if (args.Has("plot")) {
    eval::TopViewPlot plot;
    char title[256];
    std::snprintf(title, sizeof(title), "%s  ATE %.4f m (%s)",
                  args.Get("title", fs::path(est_description).filename().string()).c_str(),
                  ate.translation.rmse, alignment_label.c_str());
    plot.title = title;
    st = eval::WriteTopView(args.Get("plot"), gt, ate.est_aligned, plot);
    if (!st.ok()) {
      return Fail(st.message());
    }
    std::printf("  plot: %s\n", args.Get("plot").c_str());
  }
  Json j = Json::Object();
  j.Set("metric", "ate")
      .Set("alignment", alignment_label)
      .Set("orientation_aligned", ate.orientation_aligned);
  j.Set("ate_rmse_m", ate.translation.rmse).Set("ate_mean_m", ate.translation.mean);
  j.Set("ate_median_m", ate.translation.median).Set("ate_max_m", ate.translation.max);
  j.Set("ate_rot_rmse_deg", ate.rotation_deg.rmse).Set("scale", ate.gt_from_est.scale);
  if (rpe_status.ok()) {
    j.Set("rpe_trans_rmse_m", rpe.translation.rmse).Set("rpe_rot_rmse_deg", rpe.rotation_deg.rmse);
    j.Set("rpe_pairs", rpe.translation.count);
  }
  j.Set("ate_stats_m", StatsJson(ate.translation));
  if (rpe_status.ok()) {
    j.Set("rpe_trans_stats_m", StatsJson(rpe.translation));
  }
  j.Set("num_est", ate.num_est).Set("num_gt", ate.num_gt).Set("num_pairs", ate.pairs.size());
  j.Set("fraction_tracked", tracked);
  if (est_messages >= 0) {
    j.Set("est_messages", est_messages).Set("est_metric_messages", est_metric);
  }
  return Finish(j, args);
}

// ---------------------------------------------------------------- seg

Status LoadTruthLabels(const std::string& path, std::vector<int>* labels) {
  const std::string suffix = ".tracks.txt";
  if (path.size() > suffix.size() &&
      path.compare(path.size() - suffix.size(), suffix.size(), suffix) == 0) {
    eval::TrackSet set;
    MBSLAM_RETURN_IF_ERROR(eval::ReadTracksFile(path, &set));
    *labels = set.labels;
    return Status::Ok();
  }
  return eval::ReadLabelFile(path, labels);
}

int RunSeg(const mbslam::CommandLineArgs& args) {
  if (args.Has("pred") && args.Has("truth")) {
    std::vector<int> pred, truth;
    Status st = eval::ReadLabelFile(args.Get("pred"), &pred);
    if (st.ok()) {
      st = LoadTruthLabels(args.Get("truth"), &truth);
    }
    if (!st.ok()) {
      return Fail(st.message());
    }
    if (pred.size() != truth.size()) {
      return Fail("seg: " + std::to_string(pred.size()) + " predicted labels for " +
                  std::to_string(truth.size()) + " points");
    }
    const auto r = eval::Misclassification(pred, truth);
    std::printf(
        "misclassification: %d of %d points wrong = %.4f (%d predicted groups, %d true groups)\n",
        r.num_errors, r.num_points, r.rate, r.num_pred_groups, r.num_true_groups);
    Json j = Json::Object();
    j.Set("metric", "misclassification").Set("rate", r.rate).Set("errors", r.num_errors);
    j.Set("points", r.num_points)
        .Set("pred_groups", r.num_pred_groups)
        .Set("true_groups", r.num_true_groups);
    return Finish(j, args);
  }
  if (args.Has("pred-dir")) {
    const std::string tracks_dir = args.Get("tracks-dir", eval::DataSetPath("hopkins155"));
    if (tracks_dir.empty()) {
      return Fail("seg: no --tracks-dir and no hopkins155 under " + eval::DataRoot());
    }
    const std::string suffix = args.Get("pred-suffix", ".labels.txt");
    std::vector<eval::TrackSet> sets;
    Status st = eval::ReadTracksFolder(tracks_dir, &sets);
    if (!st.ok()) {
      return Fail(st.message());
    }
    std::map<int, std::vector<double>> by_groups;
    std::vector<double> all;
    int missing = 0;
    Json per = Json::Object();
    const bool include_dancing = args.Has("include-dancing");
    for (const auto& set : sets) {
      // Hopkins 155 is scored without its extra 'dancing' sequence (data README).
      if (set.name == "dancing" && !include_dancing) {
        continue;
      }
      const std::string pred_path = (fs::path(args.Get("pred-dir")) / (set.name + suffix)).string();
      std::vector<int> pred;
      if (!eval::ReadLabelFile(pred_path, &pred).ok() || pred.size() != set.labels.size()) {
        ++missing;
        continue;
      }
      const auto r = eval::Misclassification(pred, set.labels);
      by_groups[set.NumGroups()].push_back(r.rate);
      all.push_back(r.rate);
      per.Set(set.name, r.rate);
    }
    if (all.empty()) {
      return Fail("seg: no usable predictions in " + args.Get("pred-dir"));
    }
    Json j = Json::Object();
    j.Set("metric", "misclassification").Set("sequences", all.size()).Set("missing", missing);
    auto mean = [](const std::vector<double>& v) {
      double s = 0.0;
      for (double x : v) {
        s += x;
      }
      return v.empty() ? 0.0 : s / static_cast<double>(v.size());
    };
    for (const auto& g : by_groups) {
      std::printf("%d groups: %zu sequences, mean %.4f, median %.4f\n", g.first, g.second.size(),
                  mean(g.second), mbslam::MedianOfReport(g.second));
      j.Set(std::to_string(g.first) + "_groups_mean", mean(g.second));
      j.Set(std::to_string(g.first) + "_groups_median", mbslam::MedianOfReport(g.second));
    }
    std::printf("all: %zu sequences, mean %.4f, median %.4f (%d without predictions)\n", all.size(),
                mean(all), mbslam::MedianOfReport(all), missing);
    j.Set("all_mean", mean(all)).Set("all_median", mbslam::MedianOfReport(all)).Set("per_sequence", per);
    return Finish(j, args);
  }
  return Fail("seg: give --pred FILE --truth FILE, or --pred-dir DIR [--tracks-dir DIR]");
}

// ---------------------------------------------------------------- masks

// Features "frame_stem u v moving(0/1)" per line ('#' comments), grouped by frame.
Status ReadFeatureFile(const std::string& path,
                       std::map<std::string, std::vector<eval::LabelledFeature>>* features) {
  std::string text;
  MBSLAM_RETURN_IF_ERROR(mbslam::ReadFileToString(path, &text));
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') {
      continue;
    }
    std::istringstream ls(line);
    std::string stem;
    eval::LabelledFeature f;
    int moving = 0;
    if (!(ls >> stem >> f.u >> f.v >> moving)) {
      return Status::Error(path + ": bad feature line '" + line + "'");
    }
    f.moving = moving != 0;
    (*features)[stem].push_back(f);
  }
  return Status::Ok();
}

int RunMasks(const mbslam::CommandLineArgs& args) {
  const std::string pred_dir = args.Get("pred-dir"), gt_dir = args.Get("gt-dir");
  if (pred_dir.empty() || gt_dir.empty()) {
    return Fail("masks: give --pred-dir DIR --gt-dir DIR");
  }
  std::map<std::string, std::vector<eval::LabelledFeature>> features;
  if (args.Has("features")) {
    const Status st = ReadFeatureFile(args.Get("features"), &features);
    if (!st.ok()) {
      return Fail(st.message());
    }
  }
  std::vector<std::string> gt_files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(gt_dir, ec)) {
    if (e.path().extension() == ".png") {
      gt_files.push_back(e.path().string());
    }
  }
  std::sort(gt_files.begin(), gt_files.end());
  if (gt_files.empty()) {
    return Fail("masks: no *.png in " + gt_dir);
  }
  std::vector<double> ious;
  eval::PrecisionRecall total;
  int missing = 0;
  for (const auto& g : gt_files) {
    const std::string stem = fs::path(g).stem().string();
    cv::Mat truth, pred;
    Status st = eval::LoadBinaryMask(g, &truth);
    if (!st.ok()) {
      return Fail(st.message());
    }
    const std::string pred_path = (fs::path(pred_dir) / (stem + ".png")).string();
    if (!eval::LoadBinaryMask(pred_path, &pred).ok()) {
      ++missing;
      continue;
    }
    if (pred.size() != truth.size()) {
      return Fail("masks: size differs for " + stem);
    }
    ious.push_back(eval::RegionIoU(pred, truth));
    auto it = features.find(stem);
    if (it != features.end()) {
      total.Add(eval::MovingFeaturePrecisionRecall(it->second, truth));
    }
  }
  if (ious.empty()) {
    return Fail("masks: no predicted mask matches a ground-truth file name");
  }
  double sum = 0.0;
  for (double v : ious) {
    sum += v;
  }
  const double mean = sum / static_cast<double>(ious.size());
  std::printf("region IoU over %zu frames: mean %.4f, median %.4f (%d frames without prediction)\n",
              ious.size(), mean, mbslam::MedianOfReport(ious), missing);
  Json j = Json::Object();
  j.Set("metric", "masks").Set("frames", ious.size()).Set("missing", missing).Set("iou_mean", mean);
  j.Set("iou_median", mbslam::MedianOfReport(ious));
  if (!features.empty()) {
    std::printf("moving features: precision %.4f, recall %.4f (TP %d, FP %d, FN %d)\n",
                total.precision, total.recall, total.true_positives, total.false_positives,
                total.false_negatives);
    j.Set("precision", total.precision).Set("recall", total.recall).Set("f1", total.f1);
  }
  return Finish(j, args);
}

// ---------------------------------------------------------------- camvid

int RunCamVid(const mbslam::CommandLineArgs& args) {
  const std::string root = args.Get("root", eval::DataSetPath("camvid_0016E5_15hz"));
  if (root.empty()) {
    return Fail("camvid: no --root and no camvid_0016E5_15hz under " + eval::DataRoot());
  }
  if (!args.Has("features")) {
    return Fail("camvid: give --features FILE (\"stem u v moving\" per line)");
  }
  std::map<std::string, std::vector<eval::LabelledFeature>> features;
  Status st = ReadFeatureFile(args.Get("features"), &features);
  if (!st.ok()) {
    return Fail(st.message());
  }
  std::vector<eval::CamVidFrame> frames;
  st = eval::ReadCamVid(root, &frames);
  if (!st.ok()) {
    return Fail(st.message());
  }
  eval::CamVidFeatureStats total;
  int used = 0;
  for (const auto& f : frames) {
    auto it = features.find(fs::path(f.label).stem().string());
    if (it == features.end()) {
      continue;
    }
    const cv::Mat labels = cv::imread(f.label, cv::IMREAD_GRAYSCALE);
    if (labels.empty()) {
      return Fail("cannot read " + f.label);
    }
    total.Add(eval::CamVidMovingFeatureStats(it->second, labels));
    ++used;
  }
  std::printf(
      "CamVid: %d labelled frames with features; %d moving features: %.4f on static classes, %.4f "
      "on "
      "cars / pedestrians / bicyclists, %d on void\n",
      used, total.moving, total.static_fraction, total.movable_fraction, total.on_void);
  Json j = Json::Object();
  j.Set("metric", "camvid").Set("frames", used).Set("moving_features", total.moving);
  j.Set("static_fraction", total.static_fraction).Set("movable_fraction", total.movable_fraction);
  j.Set("void", total.on_void);
  return Finish(j, args);
}

// ---------------------------------------------------------------- objects

int RunObjects(const mbslam::CommandLineArgs& args) {
  eval::ObjectMetricsOptions options;
  options.horizon_us = args.GetInt("horizon-us", options.horizon_us);
  options.max_match_distance = args.GetDouble("max-match-m", options.max_match_distance);
  options.settle_us = args.GetInt("settle-us", options.settle_us);
  if (const std::string problems = args.ParseProblems(); !problems.empty()) return Fail(problems);
  const mbslam::ChannelOptions channels;
  if (!args.Has("est-log") || !args.Has("gt-log")) {
    return Fail("objects: give --est-log LOG --gt-log LOG");
  }
  eval::GroundTruthLog gt;
  Status st = eval::ReadGroundTruthLog(args.Get("gt-log"),
                                       args.Get("gt-channel", channels.ground_truth), &gt);
  if (!st.ok()) {
    return Fail(st.message());
  }
  std::map<int, eval::ObjectEstimate> objects;
  int messages = 0;
  st = eval::ReadObjectsLog(args.Get("est-log"),
                            args.Get("objects-channel", channels.perception_objects), &objects,
                            &messages);
  if (!st.ok()) {
    return Fail(st.message());
  }
  // The estimate's world frame, from the camera trajectories.
  eval::CameraPoseLog cam;
  st = eval::ReadCameraPoseLog(args.Get("est-log"),
                               args.Get("est-channel", channels.perception_camera_pose), &cam);
  if (!st.ok()) {
    return Fail(st.message());
  }
  eval::AteOptions ate_options;
  ate_options.alignment = args.Get("align", "sim3");
  eval::AteResult ate;
  st = eval::ComputeAte(cam.tracked, gt.camera, ate_options, &ate);
  if (!st.ok()) {
    return Fail("objects: cannot align the estimate's world frame: " + st.message());
  }
  eval::ObjectsEvaluation result;
  st = eval::EvaluateObjects(objects, gt.bodies, gt.camera, ate.gt_from_est, options, &result);
  if (!st.ok()) {
    return Fail(st.message());
  }
  std::printf(
      "objects: %d estimated, %d true bodies, %zu matched, %d unmatched estimates (camera ATE %.4f "
      "m)\n",
      result.num_est_objects, result.num_gt_bodies, result.objects.size(), result.unmatched_est,
      ate.translation.rmse);
  const double all_samples = std::max(result.est_samples, 1);
  std::printf(
      "unmatched: %d fragments (near a true body, %.3f of the samples), %d phantoms (near none, %.3f), "
      "%d short; matched estimates hold %.3f of the %d samples\n",
      result.unmatched_fragments, result.fragment_samples / all_samples, result.unmatched_phantoms,
      result.phantom_samples / all_samples, result.unmatched_short,
      (result.est_samples - result.unmatched_samples) / all_samples, result.est_samples);
  std::printf(
      "predicted volumes of every estimate near a body: %d of %d contain its true centre (%.3f), %d overlap its "
      "true box (%.3f)\n",
      result.volumes_hit_all, result.volumes_checked_all, result.hit_rate_all, result.volumes_overlapping_all,
      result.overlap_rate_all);
  Json list = Json::Array();
  for (const auto& o : result.objects) {
    std::printf(
        "  est %d -> body %d (%s): %d samples, error %.3f m, scale-aligned %.3f m, scale %.3f, "
        "depth error "
        "%.3f m, volumes %d/%d inside\n",
        o.est_id, o.gt_id, o.gt_name.c_str(), o.num_samples, o.position_error.rmse,
        o.position_error_scaled.rmse, o.best_scale, o.depth_error.rmse, o.volumes_hit,
        o.volumes_checked);
    Json oj = Json::Object();
    oj.Set("est_id", o.est_id)
        .Set("gt_id", o.gt_id)
        .Set("name", o.gt_name)
        .Set("samples", o.num_samples);
    oj.Set("position_rmse_m", o.position_error.rmse)
        .Set("position_scaled_rmse_m", o.position_error_scaled.rmse);
    oj.Set("best_scale", o.best_scale).Set("relative_scale_error", o.relative_scale_error);
    oj.Set("depth_rmse_m", o.depth_error.rmse).Set("volume_hit_rate", o.hit_rate);
    if (o.volume_ratio_median >= 0.0) oj.Set("volume_ratio_median", o.volume_ratio_median);
    oj.Set("settled_samples", o.settled_samples)
        .Set("pos_err_rel_settled_mean", o.rel_error_settled_mean)
        .Set("pos_err_rel_settled_median", o.rel_error_settled_median)
        .Set("pos_err_rel_at_settle", o.rel_error_at_settle);
    Json series = Json::Array();
    for (const auto& d : o.depth_error_over_time) {
      series.Push(d.second);
    }
    oj.Set("depth_error_over_time_m", series);
    list.Push(oj);
  }
  if (args.Has("dump")) {
    // One row per matched estimate sample: the estimate mapped into the truth world and the
    // body centre, both in the true camera's frame (x right, y down, z depth; metres), and
    // their heights above the simulated ground (world z).
    std::ostringstream csv;
    csv << "est_id,body,t_s,true_x,true_y,true_z,est_x,est_y,est_z,true_height,est_height,est_ref_depth\n";
    for (const auto& o : result.objects) {
      const auto e = objects.find(o.est_id);
      const auto b = gt.bodies.find(o.gt_id);
      if (e == objects.end() || b == gt.bodies.end()) continue;
      for (const auto& s : e->second.samples) {
        mbslam::Rigid3d body_pose, world_from_cam;
        if (!eval::InterpolatePose(b->second.poses, s.utime, 20000, &body_pose) ||
            !eval::InterpolatePose(gt.camera, s.utime, 20000, &world_from_cam)) {
          continue;
        }
        const mbslam::Rigid3d cam_from_world = world_from_cam.Inverse();
        const Eigen::Vector3d est_world = ate.gt_from_est * s.position;
        const Eigen::Vector3d t = cam_from_world * body_pose.translation;
        const Eigen::Vector3d q = cam_from_world * est_world;
        char line[512];
        std::snprintf(line, sizeof(line), "%d,%s,%.3f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n", o.est_id,
                      o.gt_name.c_str(), static_cast<double>(s.utime - gt.camera.front().utime) * 1e-6, t.x(),
                      t.y(), t.z(), q.x(), q.y(), q.z(), body_pose.translation.z(), est_world.z(),
                      s.depth >= 0.0 ? s.depth * ate.gt_from_est.scale : -1.0);
        csv << line;
      }
    }
    if (Status ws = mbslam::WriteStringAtomically(args.Get("dump"), csv.str()); !ws.ok()) return Fail(ws.message());
  }
  std::printf("predicted volumes at %lld us: %d of %d contain the true centre (%.3f); median size %.2f x the true box\n",
              static_cast<long long>(options.horizon_us), result.volumes_hit,
              result.volumes_checked, result.hit_rate, result.volume_ratio_median);
  Json j = Json::Object();
  j.Set("metric", "objects")
      .Set("est_objects", result.num_est_objects)
      .Set("gt_bodies", result.num_gt_bodies);
  j.Set("matched", result.objects.size()).Set("unmatched_est", result.unmatched_est);
  j.Set("unmatched_fragments", result.unmatched_fragments)
      .Set("unmatched_phantoms", result.unmatched_phantoms)
      .Set("unmatched_short", result.unmatched_short)
      .Set("fragment_sample_share", result.fragment_samples / all_samples)
      .Set("phantom_sample_share", result.phantom_samples / all_samples)
      .Set("matched_sample_share", (result.est_samples - result.unmatched_samples) / all_samples)
      .Set("volume_hit_rate_all", result.hit_rate_all)
      .Set("volume_overlap_rate_all", result.overlap_rate_all)
      .Set("volumes_checked_all", result.volumes_checked_all);
  j.Set("volume_hit_rate", result.hit_rate).Set("volumes_checked", result.volumes_checked);
  if (result.volume_ratio_median >= 0.0) j.Set("volume_ratio_median", result.volume_ratio_median);
  j.Set("settle_us", options.settle_us).Set("settled_samples", result.settled_samples);
  if (result.rel_error_settled_mean >= 0.0) j.Set("pos_err_rel_settled", result.rel_error_settled_mean);
  j.Set("camera_ate_rmse_m", ate.translation.rmse).Set("objects", list);
  return Finish(j, args);
}

// ---------------------------------------------------------------- reconstructions

// The shape after the points' own shift, or why there is none.
std::string ShiftedShape(const mbslam::eval::ReconstructionResult& r) {
  if (!r.shape_translated) return "(not fitted: fewer than 4 points)";
  char buf[128];
  std::snprintf(buf, sizeof(buf), "%.2f %% (median %.2f %%; shifted %.3f m)", 100.0 * r.shape_translated_err_rel,
                100.0 * r.shape_translated_err_rel_median, r.translation_fit_m);
  return buf;
}

int RunReconstructions(const mbslam::CommandLineArgs& args) {
  const int min_samples = static_cast<int>(args.GetInt("min-samples", 10));
  const int64_t max_dt = args.GetInt("max-dt-us", 20000);
  if (const std::string problems = args.ParseProblems(); !problems.empty()) return Fail(problems);
  const mbslam::ChannelOptions channels;
  if (!args.Has("dir") || !args.Has("gt-log")) {
    return Fail("reconstructions: give --dir RESULT/reconstructions --gt-log LOG");
  }
  eval::GroundTruthLog gt;
  Status st = eval::ReadGroundTruthLog(args.Get("gt-log"), args.Get("gt-channel", channels.ground_truth), &gt);
  if (!st.ok()) return Fail(st.message());
  std::vector<eval::ReconstructionEstimate> recs;
  if (std::filesystem::is_directory(args.Get("dir"))) {
    st = eval::ReadReconstructions(args.Get("dir"), &recs);
    if (!st.ok()) return Fail(st.message());
  }
  Json list = Json::Array();
  const eval::ReconstructionResult* longest = nullptr;
  std::vector<eval::ReconstructionResult> results;
  results.reserve(recs.size());
  for (const eval::ReconstructionEstimate& r : recs) {
    eval::ReconstructionResult res;
    st = eval::EvaluateReconstruction(r, gt.bodies, gt.camera, max_dt, min_samples, &res);
    if (!st.ok()) {
      std::printf("  object %d map %lld: %zu images, %zu points: %s\n", r.object_id, static_cast<long long>(r.map_id),
                  r.obj_from_cam.size(), r.points.size(), st.message().c_str());
      continue;
    }
    results.push_back(res);
  }
  for (const eval::ReconstructionResult& r : results) {
    std::printf(
        "  object %d map %lld -> body %d (%s): %d images, trajectory %.3f m = %.2f %% of the %.2f m path "
        "(%.2f %% of the %.2f m range); %d points, shape rmse %.3f m = %.2f %% of the %.2f m size (median "
        "%.2f %%, %.0f %% within 2 %%); shifted onto the box %s\n",
        r.object_id, static_cast<long long>(r.map_id), r.gt_id, r.gt_name.c_str(), r.samples, r.trajectory_rmse_m,
        100.0 * r.trajectory_err_rel_path, r.path_length_m, 100.0 * r.trajectory_err_rel_range, r.mean_range_m,
        r.num_points, r.shape_rmse_m, 100.0 * r.shape_err_rel, r.size_m, 100.0 * r.shape_err_rel_median,
        100.0 * r.share_within_2pct, ShiftedShape(r).c_str());
    Json o = Json::Object();
    o.Set("object_id", r.object_id).Set("map_id", static_cast<int64_t>(r.map_id)).Set("gt_id", r.gt_id);
    o.Set("name", r.gt_name).Set("samples", r.samples).Set("scale", r.scale);
    o.Set("path_length_m", r.path_length_m).Set("mean_range_m", r.mean_range_m);
    o.Set("trajectory_rmse_m", r.trajectory_rmse_m).Set("trajectory_err_rel_path", r.trajectory_err_rel_path);
    o.Set("trajectory_err_rel_range", r.trajectory_err_rel_range).Set("points", r.num_points);
    o.Set("shape_rmse_m", r.shape_rmse_m).Set("shape_err_rel", r.shape_err_rel);
    o.Set("shape_err_rel_median", r.shape_err_rel_median).Set("share_within_2pct", r.share_within_2pct);
    o.Set("shape_translated_rmse_m", r.shape_translated ? Json(r.shape_translated_rmse_m) : Json())
        .Set("shape_translated_err_rel", r.shape_translated ? Json(r.shape_translated_err_rel) : Json())
        .Set("shape_translated_err_rel_median", r.shape_translated ? Json(r.shape_translated_err_rel_median) : Json())
        .Set("translation_fit_m", r.shape_translated ? Json(r.translation_fit_m) : Json());
    list.Push(o);
    if (!longest || r.samples > longest->samples) longest = &r;
  }
  Json j = Json::Object();
  j.Set("metric", "reconstructions").Set("reconstructions", static_cast<int64_t>(recs.size()));
  j.Set("scored", static_cast<int64_t>(results.size()));
  if (longest) {
    // The headline is the longest-lived reconstruction (not the best one).
    std::printf(
        "longest: object %d map %lld (%s), %d images: trajectory %.2f %% of path, shape %.2f %% of size (%.2f %% "
        "shifted onto the box)\n",
        longest->object_id, static_cast<long long>(longest->map_id), longest->gt_name.c_str(), longest->samples,
        100.0 * longest->trajectory_err_rel_path, 100.0 * longest->shape_err_rel,
        longest->shape_translated ? 100.0 * longest->shape_translated_err_rel : NAN);
    j.Set("object_traj_err_rel", longest->trajectory_err_rel_path)
        .Set("object_traj_err_rel_range", longest->trajectory_err_rel_range)
        .Set("object_shape_err_rel", longest->shape_err_rel)
        .Set("object_shape_err_rel_median", longest->shape_err_rel_median)
        .Set("object_shape_translated_err_rel", longest->shape_translated ? Json(longest->shape_translated_err_rel) : Json())
        .Set("object_shape_translated_err_rel_median",
             longest->shape_translated ? Json(longest->shape_translated_err_rel_median) : Json())
        .Set("object_reconstruction_images", longest->samples)
        .Set("object_reconstruction_body", longest->gt_name);
  }
  j.Set("list", list);
  return Finish(j, args);
}

// ---------------------------------------------------------------- points

int RunPoints(const mbslam::CommandLineArgs& args) {
  const double threshold = args.GetDouble("threshold", 0.05);
  const double max_distance = args.GetDouble("max-distance", 1.0);
  if (const std::string problems = args.ParseProblems(); !problems.empty()) return Fail(problems);
  if (!args.Has("est") || !args.Has("gt")) {
    return Fail("points: give --est XYZ --gt XYZ (same frame and units)");
  }
  std::vector<Eigen::Vector3d> est, gt;
  Status st = eval::ReadPointsFile(args.Get("est"), &est);
  if (st.ok()) {
    st = eval::ReadPointsFile(args.Get("gt"), &gt);
  }
  if (!st.ok()) {
    return Fail(st.message());
  }
  const eval::ReconstructionError e = eval::CompareToSurface(est, gt, threshold, max_distance);
  std::printf(
      "reconstruction: %zu points against %zu true samples: accuracy median %.4f m, rmse %.4f m, "
      "%d beyond "
      "%.2f m; completeness %.3f within %.3f m\n",
      est.size(), gt.size(), e.accuracy.median, e.accuracy.rmse, e.outliers, max_distance,
      e.completeness, threshold);
  Json j = Json::Object();
  j.Set("metric", "points").Set("points", est.size()).Set("truth_points", gt.size());
  j.Set("accuracy_median_m", e.accuracy.median).Set("accuracy_rmse_m", e.accuracy.rmse);
  j.Set("outliers", e.outliers).Set("completeness", e.completeness).Set("threshold_m", threshold);
  return Finish(j, args);
}

// ---------------------------------------------------------------- perturb

int RunPerturb(const mbslam::CommandLineArgs& args) {
  if (!args.Has("in") || !args.Has("out")) {
    return Fail("perturb: give --in GT.tum --out EST.tum");
  }
  eval::Trajectory gt, est;
  Status st = eval::ReadTumTrajectory(args.Get("in"), &gt);
  if (!st.ok()) {
    return Fail(st.message());
  }
  eval::TrajectoryPerturbation p;
  p.gt_from_est.scale = args.GetDouble("scale", 1.0);
  Eigen::Vector3d axis(0.0, 0.0, 1.0), trans = Eigen::Vector3d::Zero();
  if (args.Has("axis") && !ParseVector3(args.Get("axis"), &axis)) {
    return Fail("perturb: --axis wants x,y,z");
  }
  if (args.Has("trans") && !ParseVector3(args.Get("trans"), &trans)) {
    return Fail("perturb: --trans wants x,y,z");
  }
  if (axis.norm() == 0.0 || !(p.gt_from_est.scale > 0.0)) {
    return Fail("perturb: bad axis or scale");
  }
  p.gt_from_est.rotation = Eigen::Quaterniond(
      Eigen::AngleAxisd(args.GetDouble("rot-deg", 0.0) * M_PI / 180.0, axis.normalized()));
  p.gt_from_est.translation = trans;
  p.noise_sigma_m = args.GetDouble("noise", 0.0);
  p.seed = static_cast<uint64_t>(args.GetInt("seed", 1));
  p.exact = !args.Has("no-exact");
  if (const std::string problems = args.ParseProblems(); !problems.empty()) return Fail(problems);
  double expected = 0.0;
  st = eval::PerturbTrajectory(gt, p, &est, &expected);
  if (st.ok()) {
    st = eval::WriteTumTrajectory(args.Get("out"), est, "perturbed copy of " + args.Get("in"));
  }
  if (!st.ok()) {
    return Fail(st.message());
  }
  std::printf("wrote %zu poses to %s: est = S^-1 (gt + n), scale %.6f, noise rms %.6f m%s\n",
              est.size(), args.Get("out").c_str(), p.gt_from_est.scale, expected,
              p.exact ? " (exact)" : "");
  Json j = Json::Object();
  j.Set("metric", "perturb").Set("poses", est.size()).Set("scale", p.gt_from_est.scale);
  j.Set("expected_ate_sim3_m", expected).Set("exact", p.exact);
  return Finish(j, args);
}

int RunPerturbLabels(const mbslam::CommandLineArgs& args) {
  if (!args.Has("truth") || !args.Has("out")) {
    return Fail("perturb-labels: give --truth FILE --out FILE");
  }
  std::vector<int> truth, pred;
  Status st = LoadTruthLabels(args.Get("truth"), &truth);
  if (!st.ok()) {
    return Fail(st.message());
  }
  eval::LabelPerturbation p;
  p.wrong = static_cast<int>(args.GetInt("wrong", 0));
  p.split = static_cast<int>(args.GetInt("split", 0));
  p.merge_smallest = args.Has("merge");
  p.permute = !args.Has("no-permute");
  p.seed = static_cast<uint64_t>(args.GetInt("seed", 1));
  if (const std::string problems = args.ParseProblems(); !problems.empty()) return Fail(problems);
  int expected = 0;
  st = eval::PerturbLabels(truth, p, &pred, &expected);
  if (st.ok()) {
    st = eval::WriteLabelFile(args.Get("out"), pred);
  }
  if (!st.ok()) {
    return Fail(st.message());
  }
  const double rate =
      truth.empty() ? 0.0 : static_cast<double>(expected) / static_cast<double>(truth.size());
  std::printf("wrote %zu labels to %s with %d known errors (rate %.6f)\n", pred.size(),
              args.Get("out").c_str(), expected, rate);
  Json j = Json::Object();
  j.Set("metric", "perturb-labels").Set("points", truth.size()).Set("expected_errors", expected);
  j.Set("expected_rate", rate);
  return Finish(j, args);
}

// ---------------------------------------------------------------- datasets

int RunDatasets(const mbslam::CommandLineArgs& args) {
  Json j = Json::Object();
  j.Set("metric", "datasets").Set("root", eval::DataRoot());
  std::printf("data root: %s\n", eval::DataRoot().c_str());
  auto report = [&](const std::string& name, const std::string& text, const Json& info) {
    std::printf("  %-26s %s\n", name.c_str(), text.c_str());
    j.Set(name, info);
  };
  if (const std::string p = eval::DataSetPath("hopkins155"); !p.empty()) {
    std::vector<eval::TrackSet> sets;
    const Status st = eval::ReadTracksFolder(p, &sets);
    if (!st.ok()) {
      return Fail(st.message());
    }
    std::map<int, int> by_groups;
    for (const auto& s : sets) {
      ++by_groups[s.NumGroups()];
    }
    std::string text = std::to_string(sets.size()) + " sequences (";
    Json info = Json::Object();
    info.Set("sequences", sets.size());
    bool first = true;
    for (const auto& g : by_groups) {
      text += (first ? "" : ", ") + std::to_string(g.second) + " with " + std::to_string(g.first) +
              " groups";
      first = false;
      info.Set(std::to_string(g.first) + "_groups", g.second);
    }
    report("hopkins155", text + ")", info);
  }
  if (const std::string p = eval::DataSetPath("davis2016"); !p.empty()) {
    std::vector<eval::DavisSequence> seqs;
    const Status st = eval::ReadDavis(p, &seqs);
    if (!st.ok()) {
      return Fail(st.message());
    }
    size_t frames = 0;
    for (const auto& s : seqs) {
      frames += s.masks.size();
    }
    report("davis2016",
           std::to_string(seqs.size()) + " sequences, " + std::to_string(frames) + " masked frames",
           Json::Object().Set("sequences", seqs.size()).Set("frames", frames));
  }
  if (const std::string p = eval::DataSetPath("camvid_0016E5_15hz"); !p.empty()) {
    std::vector<eval::CamVidFrame> frames;
    const Status st = eval::ReadCamVid(p, &frames);
    if (!st.ok()) {
      return Fail(st.message());
    }
    report("camvid_0016E5_15hz", std::to_string(frames.size()) + " labelled frames",
           Json::Object().Set("frames", frames.size()));
  }
  if (const std::string p = eval::DataSetPath("tum_fr3_cabinet_subset"); !p.empty()) {
    eval::TumSubset tum;
    const Status st = eval::ReadTumSubset(p, &tum);
    if (!st.ok()) {
      return Fail(st.message());
    }
    report("tum_fr3_cabinet_subset", std::to_string(tum.truth.size()) + " poses and images",
           Json::Object().Set("frames", tum.truth.size()));
  }
  if (const std::string p = eval::DataSetPath("tartanair_indoor_subset"); !p.empty()) {
    eval::TartanAirSubset ta;
    const Status st = eval::ReadTartanAirSubset(p, 1000000, &ta);
    if (!st.ok()) {
      return Fail(st.message());
    }
    double length = 0.0;
    for (size_t i = 1; i < ta.truth.size(); ++i) {
      length += (ta.truth[i].pose.translation - ta.truth[i - 1].pose.translation).norm();
    }
    report("tartanair_indoor_subset",
           std::to_string(ta.truth.size()) + " poses and images, path " + std::to_string(length) +
               " m",
           Json::Object().Set("frames", ta.truth.size()).Set("path_length_m", length));
  }
  return Finish(j, args);
}

void Usage() {
  std::cerr << R"(usage: mbslam-eval SUBCOMMAND [--options]
  ate      camera trajectory: ATE (Sim(3)/SE(3)/no alignment), RPE, fraction tracked
           --est F.tum | --est-log LOG [--est-channel C]
           --gt F.tum | --gt-log LOG [--gt-channel C] | --gt-sequence DIR | --gt-tartanair pose_left.txt
           [--align sim3|se3|none] [--max-dt-us N] [--rpe-delta N | --rpe-delta-us N] [--plot OUT.png] [--title T]
           [--align-est OTHER.tum (--align-gt F.tum | --align-gt-log LOG | --align-gt-sequence DIR |
            --align-gt-tartanair pose_left.txt)]: the alignment of another run
           (in the same map) against its truth, applied as it is
  seg      track misclassification (Hungarian matching)
           --pred LABELS --truth LABELS|X.tracks.txt
           --pred-dir DIR [--tracks-dir DIR (default: Hopkins 155)] [--pred-suffix .labels.txt] [--include-dancing]
  masks    region IoU and moving-feature precision / recall
           --pred-dir DIR --gt-dir DIR [--features FILE ("stem u v moving" per line)]
  camvid   where features labelled moving fall in CamVid's classes (false detections on static classes)
           --features FILE ("stem u v moving" per line) [--root DIR]
  objects  per-object trajectory / scale / depth errors and predicted-volume hit rate
           --est-log LOG --gt-log LOG [--horizon-us N] [--align sim3|se3] [--max-match-m M] [--settle-us N]
           [--dump FILE.csv: per matched sample, truth and estimate in the true camera frame]
  reconstructions  moving objects' own reconstructions (result/reconstructions/): camera-relative
           trajectory and shape (point-to-box distance) after a similarity, per body, and the shape
           again after the points' own shift onto the box (4 points at least)
           --dir DIR --gt-log LOG [--min-samples 10] [--max-dt-us N]
           (env EVAL_DUMP_SHAPE set, to any value: each scored point in its body's frame and its distance,
           unshifted and shifted, to stderr)
  points   reconstruction accuracy / completeness against ground-truth surface points
           --est XYZ --gt XYZ (e.g. <sequence>/points/<id>.txt) [--threshold 0.05] [--max-distance 1.0]
  perturb  write a trajectory with a known similarity and noise (expected ATE printed)
           --in GT.tum --out EST.tum [--scale S] [--rot-deg A] [--axis x,y,z] [--trans x,y,z] [--noise M] [--seed N] [--no-exact]
  perturb-labels  write labels with a known number of errors
           --truth LABELS|X.tracks.txt --out FILE [--wrong K] [--split M] [--merge] [--no-permute] [--seed N]
  datasets what of ../shared/data ($MBSLAM_DATA) is present
every subcommand accepts --json FILE and prints one JSON object as its last line.
)";
}

}  // namespace

static int Main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help") {
    Usage();
    return argc < 2 ? 2 : 0;
  }
  const std::string cmd = argv[1];
  const mbslam::CommandLineArgs args(argc, argv, 2);
  if (cmd == "ate") {
    return RunAte(args);
  }
  if (cmd == "seg") {
    return RunSeg(args);
  }
  if (cmd == "masks") {
    return RunMasks(args);
  }
  if (cmd == "objects") {
    return RunObjects(args);
  }
  if (cmd == "reconstructions") {
    return RunReconstructions(args);
  }
  if (cmd == "camvid") {
    return RunCamVid(args);
  }
  if (cmd == "points") {
    return RunPoints(args);
  }
  if (cmd == "perturb") {
    return RunPerturb(args);
  }
  if (cmd == "perturb-labels") {
    return RunPerturbLabels(args);
  }
  if (cmd == "datasets") {
    return RunDatasets(args);
  }
  std::cerr << "mbslam-eval: unknown subcommand '" << cmd << "'\n";
  Usage();
  return 2;
}

int main(int argc, char** argv) {
  try {
    return Main(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "mbslam-eval: " << e.what() << "\n";
    return 1;
  }
}
