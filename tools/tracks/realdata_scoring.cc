#include "tools/tracks/realdata_scoring.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <limits>
#include <utility>

#include "common/lcm/lcm_log.h"
#include "common/lcm/wire_check.h"
#include "mbslam/objects_t.hpp"
#include "mbslam/tracks_t.hpp"

namespace mbslam {
namespace eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

ImagePolygon ToPolygon(const mbslam::image_hull_t& h) {
  ImagePolygon p;
  p.body_id = h.body_id;
  const size_t n = std::min({static_cast<size_t>(std::max(h.num_points, 0)), h.u.size(), h.v.size()});
  for (size_t i = 0; i < n; ++i) {
    if (std::isfinite(h.u[i]) && std::isfinite(h.v[i])) p.points.emplace_back(h.u[i], h.v[i]);
  }
  return p;
}

std::vector<std::vector<cv::Point2f>> Points(const std::vector<ImagePolygon>& polygons) {
  std::vector<std::vector<cv::Point2f>> out;
  for (const ImagePolygon& p : polygons) {
    if (p.points.size() >= 3) out.push_back(p.points);
  }
  return out;
}

// Distance (px) of every pixel to the nearest non-zero pixel of `truth` (large if none).
cv::Mat DistanceToTruth(const cv::Mat& truth) {
  cv::Mat outside = truth == 0, dist;
  if (cv::countNonZero(truth) == 0) return cv::Mat(truth.size(), CV_32F, cv::Scalar(1e9));
  cv::distanceTransform(outside, dist, cv::DIST_L2, 3);
  return dist;
}

double Mean(const std::vector<double>& v) {
  if (v.empty()) return kNaN;
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

}  // namespace

bool ScoredTrack(const mbslam::feature_track_t& track) {
  return (track.flags & (mbslam::feature_track_t::FLAG_OCCLUDED | mbslam::feature_track_t::FLAG_NEW)) == 0 &&
         std::isfinite(track.u) && std::isfinite(track.v);
}

bool LabelledMoving(int body_id) { return body_id > 0; }

Status ReadPerceptionFrames(const std::string& log_path, const ChannelOptions& channels,
                            std::map<int64_t, PerceptionFrame>* frames, int* num_undecodable) {
  frames->clear();
  Status status;
  std::unique_ptr<LcmLogReader> reader = LcmLogReader::Open(log_path, &status);
  if (!reader) return status;
  int bad = 0;
  LcmLogEvent e;
  while (reader->Next(&e)) {
    if (e.channel == channels.perception_tracks) {
      mbslam::tracks_t t{};
      if (!DecodeLcmMessage(e.data.data(), e.data.size(), &t).ok()) {
        ++bad;
        continue;
      }
      PerceptionFrame& f = (*frames)[t.frame_seq];
      f.frame_seq = t.frame_seq;
      f.utime = t.utime;
      f.width = t.width;
      f.height = t.height;
      f.has_tracks = true;
      f.features.clear();
      f.body_ids.clear();
      f.tracks.clear();
      f.num_unassigned = f.num_skipped = 0;
      for (const auto& tr : t.tracks) {
        if (!ScoredTrack(tr)) {
          ++f.num_skipped;
          continue;
        }
        LabelledFeature lf;
        lf.u = tr.u;
        lf.v = tr.v;
        lf.moving = LabelledMoving(tr.body_id);
        f.features.push_back(lf);
        f.body_ids.push_back(tr.body_id);
        f.tracks.push_back(tr);
        f.num_unassigned += tr.body_id < 0;
      }
      f.track_hulls.clear();
      for (const auto& h : t.hulls) {
        if (h.body_id > 0) f.track_hulls.push_back(ToPolygon(h));
      }
    } else if (e.channel == channels.perception_objects) {
      mbslam::objects_t o{};
      if (!DecodeLcmMessage(e.data.data(), e.data.size(), &o).ok()) {
        ++bad;
        continue;
      }
      PerceptionFrame& f = (*frames)[o.frame_seq];
      f.frame_seq = o.frame_seq;
      if (f.utime == 0) f.utime = o.utime;
      f.has_objects = true;
      f.object_hulls.clear();
      for (const auto& obj : o.objects) {
        ImagePolygon p = ToPolygon(obj.hull);
        p.body_id = obj.id;
        if (p.points.size() >= 3) f.object_hulls.push_back(std::move(p));
      }
    }
  }
  if (num_undecodable) *num_undecodable = bad;
  return Status::Ok();
}

const char* RegionSourceName(RegionSource source) {
  switch (source) {
    case RegionSource::kObjectHulls: return "object_hulls";
    case RegionSource::kTrackHulls: return "track_hulls";
    case RegionSource::kFeatureHulls: return "feature_hulls";
    case RegionSource::kNone: break;
  }
  return "none";
}

cv::Mat MovingRegion(const PerceptionFrame& frame, cv::Size size, RegionSource* source) {
  RegionSource src = RegionSource::kNone;
  std::vector<std::vector<cv::Point2f>> polygons = Points(frame.object_hulls);
  if (!polygons.empty()) {
    src = RegionSource::kObjectHulls;
  } else if (!frame.has_objects && !(polygons = Points(frame.track_hulls)).empty()) {
    src = RegionSource::kTrackHulls;
  } else if (!frame.has_objects) {
    std::map<int, std::vector<cv::Point2f>> per_body;
    for (size_t i = 0; i < frame.features.size(); ++i) {
      if (frame.features[i].moving) {
        per_body[frame.body_ids[i]].emplace_back(static_cast<float>(frame.features[i].u),
                                                 static_cast<float>(frame.features[i].v));
      }
    }
    for (auto& [body, pts] : per_body) {
      if (pts.size() < 3) continue;
      std::vector<cv::Point2f> hull;
      cv::convexHull(pts, hull);
      if (hull.size() >= 3) polygons.push_back(std::move(hull));
    }
    if (!polygons.empty()) src = RegionSource::kFeatureHulls;
  }
  if (source) *source = src;
  return RasterizePolygons(polygons, size);
}

double ConvexHullIoU(const cv::Mat& mask) {
  if (cv::countNonZero(mask) == 0) return 1.0;
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  std::vector<std::vector<cv::Point>> hulls;
  for (const auto& c : contours) {
    std::vector<cv::Point> hull;
    cv::convexHull(c, hull);
    hulls.push_back(std::move(hull));
  }
  cv::Mat region(mask.size(), CV_8UC1, cv::Scalar(0));
  cv::fillPoly(region, hulls, cv::Scalar(255));
  for (const auto& h : hulls) cv::polylines(region, std::vector<std::vector<cv::Point>>{h}, true, cv::Scalar(255));
  return RegionIoU(region, mask);
}

MaskFrameScore ScoreMaskFrame(const PerceptionFrame* frame, const cv::Mat& mask) {
  CV_Assert(mask.type() == CV_8UC1);
  MaskFrameScore s;
  cv::Mat region(mask.size(), CV_8UC1, cv::Scalar(0));
  if (frame != nullptr && frame->has_tracks) {
    s.frame_seq = frame->frame_seq;
    s.has_output = true;
    s.counts = MovingFeaturePrecisionRecall(frame->features, mask);
    std::vector<LabelledFeature> non_static = frame->features;
    for (size_t i = 0; i < non_static.size(); ++i) non_static[i].moving = frame->body_ids[i] != 0;
    s.counts_with_unassigned = MovingFeaturePrecisionRecall(non_static, mask);
    for (size_t i = 0; i < frame->features.size(); ++i) {
      const LabelledFeature& f = frame->features[i];
      const int x = static_cast<int>(std::lround(f.u)), y = static_cast<int>(std::lround(f.v));
      if (x < 0 || y < 0 || x >= mask.cols || y >= mask.rows) continue;
      ++s.num_features;
      s.num_moving += f.moving;
      s.num_unassigned += frame->body_ids[i] < 0;
    }
    region = MovingRegion(*frame, mask.size(), &s.region_source);
    if (s.counts.false_positives > 0) {
      const cv::Mat dist = DistanceToTruth(mask);
      for (const LabelledFeature& f : frame->features) {
        const int x = static_cast<int>(std::lround(f.u)), y = static_cast<int>(std::lround(f.v));
        if (!f.moving || x < 0 || y < 0 || x >= mask.cols || y >= mask.rows || mask.at<uint8_t>(y, x)) continue;
        s.fp_near_mask += dist.at<float>(y, x) <= kNearTruthPx;
      }
    }
  }
  const int tp = s.counts.true_positives, fp = s.counts.false_positives, fn = s.counts.false_negatives;
  s.precision = tp + fp > 0 ? static_cast<double>(tp) / (tp + fp) : kNaN;
  s.recall = tp + fn > 0 ? static_cast<double>(tp) / (tp + fn) : kNaN;
  s.iou = RegionIoU(region, mask);
  return s;
}

MaskSequenceScore SummarizeMaskSequence(const std::string& name,
                                        const std::vector<MaskFrameScore>& frames) {
  MaskSequenceScore s;
  s.name = name;
  s.per_frame = frames;
  std::vector<double> p, r, j;
  for (const MaskFrameScore& f : frames) {
    ++s.frames;
    s.frames_without_output += !f.has_output;
    if (std::isnan(f.precision)) {
      ++s.frames_precision_undefined;
    } else {
      p.push_back(f.precision);
    }
    if (std::isnan(f.recall)) {
      ++s.frames_recall_undefined;
    } else {
      r.push_back(f.recall);
    }
    j.push_back(f.iou);
    s.pooled.Add(f.counts);
    s.pooled_with_unassigned.Add(f.counts_with_unassigned);
    s.unassigned += f.num_unassigned;
    s.fp_near_mask += f.fp_near_mask;
    ++s.region_sources[f.region_source];
  }
  s.pooled.Finish();
  s.pooled_with_unassigned.Finish();
  s.mean_precision = Mean(p);
  s.mean_recall = Mean(r);
  s.mean_iou = Mean(j);
  return s;
}

Status ScoreDavisSequence(const DavisSequence& sequence,
                          const std::map<int64_t, PerceptionFrame>& run, MaskSequenceScore* score) {
  std::vector<MaskFrameScore> frames;
  std::vector<double> ceiling;
  for (size_t i = 0; i < sequence.masks.size(); ++i) {
    cv::Mat mask;
    MBSLAM_RETURN_IF_ERROR(LoadBinaryMask(sequence.masks[i], &mask));
    ceiling.push_back(ConvexHullIoU(mask));
    auto it = run.find(static_cast<int64_t>(i));
    const PerceptionFrame* f = it == run.end() ? nullptr : &it->second;
    if (f != nullptr && f->has_tracks && (f->width != mask.cols || f->height != mask.rows)) {
      return Status::Error(sequence.name + ": run image " + std::to_string(f->width) + "x" +
                           std::to_string(f->height) + " differs from mask " + sequence.masks[i]);
    }
    MaskFrameScore fs = ScoreMaskFrame(f, mask);
    fs.frame_seq = static_cast<int64_t>(i);
    frames.push_back(fs);
  }
  *score = SummarizeMaskSequence(sequence.name, frames);
  score->mean_hull_iou_ceiling = Mean(ceiling);
  return Status::Ok();
}

MaskDatasetScore SummarizeMaskDataset(const std::vector<MaskSequenceScore>& sequences) {
  MaskDatasetScore d;
  std::vector<double> p, r, j;
  for (const MaskSequenceScore& s : sequences) {
    ++d.sequences;
    if (!std::isnan(s.mean_precision)) p.push_back(s.mean_precision);
    if (!std::isnan(s.mean_recall)) r.push_back(s.mean_recall);
    if (!std::isnan(s.mean_iou)) j.push_back(s.mean_iou);
    d.pooled.Add(s.pooled);
    d.pooled_with_unassigned.Add(s.pooled_with_unassigned);
  }
  d.pooled.Finish();
  d.pooled_with_unassigned.Finish();
  d.mean_precision = Mean(p);
  d.mean_recall = Mean(r);
  d.mean_iou = Mean(j);
  return d;
}

void CamVidRunScore::AddFrame(const PerceptionFrame& frame, const cv::Mat& labels) {
  CV_Assert(labels.type() == CV_8UC1);
  ++frames;
  moving.Add(CamVidMovingFeatureStats(frame.features, labels));
  std::vector<LabelledFeature> ns = frame.features;
  for (size_t i = 0; i < ns.size(); ++i) ns[i].moving = frame.body_ids[i] != 0;
  non_static.Add(CamVidMovingFeatureStats(ns, labels));
  cv::Mat movable(labels.size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < labels.rows; ++y) {
    for (int x = 0; x < labels.cols; ++x) {
      if (IsCamVidMovableClass(labels.at<uint8_t>(y, x))) movable.at<uint8_t>(y, x) = 255;
    }
  }
  const cv::Mat dist = DistanceToTruth(movable);
  for (size_t i = 0; i < frame.features.size(); ++i) {
    const LabelledFeature& f = frame.features[i];
    const int x = static_cast<int>(std::lround(f.u)), y = static_cast<int>(std::lround(f.v));
    if (x < 0 || y < 0 || x >= labels.cols || y >= labels.rows) continue;
    const int label = labels.at<uint8_t>(y, x);
    ++features;
    ++per_class[label];
    unassigned += frame.body_ids[i] < 0;
    if (f.moving) ++moving_per_class[label];
    if (IsCamVidMovableClass(label)) {
      ++on_movable;
      on_movable_moving += f.moving;
    } else if (IsCamVidStaticClass(label)) {
      ++on_static;
      moving_on_static_near_movable += f.moving && dist.at<float>(y, x) <= kNearTruthPx;
    }
  }
}

void CamVidRunScore::Finish() {
  moving.Add(CamVidFeatureStats());  // recomputes the fractions
  non_static.Add(CamVidFeatureStats());
  non_static_on_static = non_static.static_fraction;
  moving_on_static = moving.static_fraction;
  moving_on_movable = moving.movable_fraction;
  movable_labelled_moving = on_movable > 0 ? static_cast<double>(on_movable_moving) / on_movable : 0.0;
  static_labelled_moving = on_static > 0 ? static_cast<double>(moving.on_static) / on_static : 0.0;
}

Status ScoreCamVid(const std::vector<CamVidFrame>& frames,
                   const std::map<int64_t, PerceptionFrame>& run, CamVidRunScore* score) {
  *score = CamVidRunScore();
  for (size_t i = 0; i < frames.size(); ++i) {
    auto it = run.find(static_cast<int64_t>(i));
    if (it == run.end() || !it->second.has_tracks) {
      ++score->frames_without_output;
      continue;
    }
    const cv::Mat labels = cv::imread(frames[i].label, cv::IMREAD_GRAYSCALE);
    if (labels.empty()) return Status::Error("cannot read " + frames[i].label);
    if (it->second.width != labels.cols || it->second.height != labels.rows) {
      return Status::Error("run image size differs from " + frames[i].label);
    }
    score->AddFrame(it->second, labels);
  }
  score->Finish();
  return Status::Ok();
}

void StaticSceneScore::AddFrame(const PerceptionFrame& frame) {
  if (!frame.has_tracks) return;
  ++frames;
  int moving_here = 0;
  for (size_t i = 0; i < frame.features.size(); ++i) {
    ++features;
    if (!frame.features[i].moving) continue;
    ++moving_here;
    objects.insert(frame.body_ids[i]);
  }
  moving += moving_here;
  unassigned += frame.num_unassigned;
  frames_with_moving += moving_here > 0;
}

void StaticSceneScore::Finish() {
  false_moving = features > 0 ? static_cast<double>(moving) / features : 0.0;
  frames_with_moving_share = frames > 0 ? static_cast<double>(frames_with_moving) / frames : 0.0;
}

StaticSceneScore ScoreStaticScene(const std::map<int64_t, PerceptionFrame>& run) {
  StaticSceneScore score;
  for (const auto& [seq, frame] : run) score.AddFrame(frame);
  score.Finish();
  return score;
}

}  // namespace eval
}  // namespace mbslam
