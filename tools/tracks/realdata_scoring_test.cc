// Known answers for the real-data scorers on synthetic masks, label images and logs.

#include "tools/tracks/realdata_scoring.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "common/lcm/lcm_log.h"
#include "mbslam/objects_t.hpp"
#include "mbslam/tracks_t.hpp"
#include "test/tools/feature_tracks.h"

namespace mbslam {
namespace eval {
namespace {

namespace fs = std::filesystem;

using FT = mbslam::feature_track_t;

// A 100x100 mask with the square x, y in [20, 60) set.
cv::Mat SquareMask(int x0 = 20, int y0 = 20, int side = 40, cv::Size size = {100, 100}) {
  cv::Mat m(size, CV_8UC1, cv::Scalar(0));
  m(cv::Rect(x0, y0, side, side)).setTo(255);
  return m;
}

PerceptionFrame FrameWith(const std::vector<std::tuple<double, double, int>>& features) {
  PerceptionFrame f;
  f.frame_seq = 0;
  f.width = f.height = 100;
  f.has_tracks = true;
  for (const auto& [u, v, body] : features) {
    LabelledFeature lf;
    lf.u = u;
    lf.v = v;
    lf.moving = LabelledMoving(body);
    f.features.push_back(lf);
    f.body_ids.push_back(body);
  }
  return f;
}

// k_in_moving inside labelled moving, k_in_static inside static, and so on.
PerceptionFrame Counted(int in_moving, int in_static, int out_moving, int out_static, int out_unassigned = 0) {
  std::vector<std::tuple<double, double, int>> feats;
  for (int i = 0; i < in_moving; ++i) feats.emplace_back(25 + i, 30, 1);
  for (int i = 0; i < in_static; ++i) feats.emplace_back(25 + i, 50, 0);
  for (int i = 0; i < out_moving; ++i) feats.emplace_back(70 + i, 80, 2);
  for (int i = 0; i < out_static; ++i) feats.emplace_back(5, 5 + i, 0);
  for (int i = 0; i < out_unassigned; ++i) feats.emplace_back(90, 5 + i, -1);
  return FrameWith(feats);
}

ImagePolygon Square(int body, float x0, float y0, float x1, float y1) {
  ImagePolygon p;
  p.body_id = body;
  p.points = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  return p;
}

TEST(RealDataScoring, FeatureFilterAndLabel) {
  FT t{};
  t.u = 3;
  t.v = 4;
  EXPECT_TRUE(ScoredTrack(t));
  t.flags = FT::FLAG_NEW;
  EXPECT_FALSE(ScoredTrack(t));
  t.flags = FT::FLAG_OCCLUDED;
  EXPECT_FALSE(ScoredTrack(t));
  t.flags = FT::FLAG_HAS_3D;
  EXPECT_TRUE(ScoredTrack(t));
  t.u = NAN;
  EXPECT_FALSE(ScoredTrack(t));
  EXPECT_TRUE(LabelledMoving(3));
  EXPECT_FALSE(LabelledMoving(0));
  EXPECT_FALSE(LabelledMoving(-1));  // unassigned is not "moving"
}

TEST(RealDataScoring, PrecisionRecallFromKnownCounts) {
  // 6 moving inside, 2 static inside, 3 moving outside, 9 static outside, 4 unassigned outside:
  // precision 6 / 9, recall 6 / 8.
  const PerceptionFrame f = Counted(6, 2, 3, 9, 4);
  const MaskFrameScore s = ScoreMaskFrame(&f, SquareMask());
  EXPECT_TRUE(s.has_output);
  EXPECT_EQ(s.counts.true_positives, 6);
  EXPECT_EQ(s.counts.false_positives, 3);
  EXPECT_EQ(s.counts.false_negatives, 2);
  EXPECT_EQ(s.counts.true_negatives, 13);
  EXPECT_DOUBLE_EQ(s.precision, 6.0 / 9.0);
  EXPECT_DOUBLE_EQ(s.recall, 6.0 / 8.0);
  EXPECT_EQ(s.num_features, 24);
  EXPECT_EQ(s.num_moving, 9);
  EXPECT_EQ(s.num_unassigned, 4);
  // Unassigned taken as moving: 4 more false positives.
  EXPECT_EQ(s.counts_with_unassigned.true_positives, 6);
  EXPECT_EQ(s.counts_with_unassigned.false_positives, 7);
  EXPECT_EQ(s.counts_with_unassigned.false_negatives, 2);
}

TEST(RealDataScoring, FalsePositivesNearTheTruthAreCounted) {
  // Mask [20, 60)^2; moving features 3 px right of it (near), 16 px right (far), inside (TP).
  const PerceptionFrame f = FrameWith({{62, 40, 1}, {75, 40, 1}, {40, 40, 1}, {62, 45, 0}});
  const MaskFrameScore s = ScoreMaskFrame(&f, SquareMask());
  EXPECT_EQ(s.counts.false_positives, 2);
  EXPECT_EQ(s.fp_near_mask, 1);
  // CamVid: car at x >= 50; moving on road 4 px (near) and 30 px (far) from it.
  cv::Mat labels(100, 100, CV_8UC1, cv::Scalar(kCamVidRoad));
  labels(cv::Rect(50, 0, 50, 100)).setTo(kCamVidCar);
  CamVidRunScore c;
  c.AddFrame(FrameWith({{46, 10, 1}, {20, 10, 1}, {70, 10, 1}}), labels);
  c.Finish();
  EXPECT_EQ(c.moving.on_static, 2);
  EXPECT_EQ(c.moving_on_static_near_movable, 1);
}

TEST(RealDataScoring, UndefinedPrecisionAndRecall) {
  const PerceptionFrame none_moving = Counted(0, 3, 0, 5);
  MaskFrameScore s = ScoreMaskFrame(&none_moving, SquareMask());
  EXPECT_TRUE(std::isnan(s.precision));
  EXPECT_DOUBLE_EQ(s.recall, 0.0);
  const PerceptionFrame none_inside = Counted(0, 0, 4, 5);
  s = ScoreMaskFrame(&none_inside, SquareMask());
  EXPECT_DOUBLE_EQ(s.precision, 0.0);
  EXPECT_TRUE(std::isnan(s.recall));
  // No output at all: nothing defined but the IoU, which is 0 against a non-empty mask.
  s = ScoreMaskFrame(nullptr, SquareMask());
  EXPECT_FALSE(s.has_output);
  EXPECT_TRUE(std::isnan(s.precision));
  EXPECT_TRUE(std::isnan(s.recall));
  EXPECT_DOUBLE_EQ(s.iou, 0.0);
  // ... and 1 against an empty mask.
  s = ScoreMaskFrame(nullptr, cv::Mat(100, 100, CV_8UC1, cv::Scalar(0)));
  EXPECT_DOUBLE_EQ(s.iou, 1.0);
}

TEST(RealDataScoring, SquareHullVersusSquareMaskIoU) {
  // Hull with integer vertices (20,20)-(59,59) covers the pixels 20..59: exactly the mask.
  PerceptionFrame f = Counted(5, 0, 0, 0);
  f.has_objects = true;
  f.object_hulls = {Square(1, 20, 20, 59, 59)};
  MaskFrameScore s = ScoreMaskFrame(&f, SquareMask());
  EXPECT_EQ(s.region_source, RegionSource::kObjectHulls);
  EXPECT_DOUBLE_EQ(s.iou, 1.0);
  // Mask shifted by 10 px in x: intersection 30 x 40, union 50 x 40 -> 0.6.
  s = ScoreMaskFrame(&f, SquareMask(30, 20));
  EXPECT_DOUBLE_EQ(s.iou, 0.6);
  // Hull a quarter of the mask (20x20 inside the 40x40 square): 400 / 1600.
  f.object_hulls = {Square(1, 20, 20, 39, 39)};
  s = ScoreMaskFrame(&f, SquareMask());
  EXPECT_DOUBLE_EQ(s.iou, 0.25);
  // Two objects: the union of their hulls (two disjoint 20x40 halves) = the mask.
  f.object_hulls = {Square(1, 20, 20, 39, 59), Square(2, 40, 20, 59, 59)};
  s = ScoreMaskFrame(&f, SquareMask());
  EXPECT_DOUBLE_EQ(s.iou, 1.0);
}

TEST(RealDataScoring, ConvexHullIoUCeiling) {
  EXPECT_DOUBLE_EQ(ConvexHullIoU(SquareMask()), 1.0);  // convex
  // An L: the 40x40 square minus its 20x20 top-right quarter; the hull adds the triangle
  // above the diagonal from (39,20)-(59,40): about half the quarter.
  cv::Mat l = SquareMask();
  l(cv::Rect(40, 20, 20, 20)).setTo(0);
  const double iou = ConvexHullIoU(l);
  EXPECT_GT(iou, 1200.0 / 1420.0 - 0.01);
  EXPECT_LT(iou, 1200.0 / 1380.0 + 0.01);
  EXPECT_DOUBLE_EQ(ConvexHullIoU(cv::Mat(10, 10, CV_8UC1, cv::Scalar(0))), 1.0);
  // Two separate squares: one hull each, exactly the mask.
  cv::Mat two = SquareMask(5, 5, 10);
  two(cv::Rect(70, 70, 20, 20)).setTo(255);
  EXPECT_DOUBLE_EQ(ConvexHullIoU(two), 1.0);
}

TEST(RealDataScoring, RegionSourceFallbacks) {
  // Moving features of body 3 at the corners of the square (20,20)-(59,59) and one inside.
  PerceptionFrame f = FrameWith({{20, 20, 3}, {59, 20, 3}, {59, 59, 3}, {20, 59, 3}, {40, 40, 3}, {80, 80, 0}});
  RegionSource src;
  // No objects_t, no hulls on tracks_t: convex hull of the moving features.
  cv::Mat r = MovingRegion(f, {100, 100}, &src);
  EXPECT_EQ(src, RegionSource::kFeatureHulls);
  EXPECT_DOUBLE_EQ(RegionIoU(r, SquareMask()), 1.0);
  // Hulls on tracks_t but no objects_t.
  f.track_hulls = {Square(3, 20, 20, 39, 39)};
  r = MovingRegion(f, {100, 100}, &src);
  EXPECT_EQ(src, RegionSource::kTrackHulls);
  EXPECT_EQ(cv::countNonZero(r), 400);
  // objects_t present: its hulls win.
  f.has_objects = true;
  f.object_hulls = {Square(3, 40, 40, 59, 59)};
  r = MovingRegion(f, {100, 100}, &src);
  EXPECT_EQ(src, RegionSource::kObjectHulls);
  EXPECT_EQ(r.at<uint8_t>(50, 50), 255);
  EXPECT_EQ(r.at<uint8_t>(30, 30), 0);
  // objects_t without objects: nothing moving, empty region.
  f.object_hulls.clear();
  r = MovingRegion(f, {100, 100}, &src);
  EXPECT_EQ(src, RegionSource::kNone);
  EXPECT_EQ(cv::countNonZero(r), 0);
}

TEST(RealDataScoring, SequenceMeansExcludeAndCountUndefinedFrames) {
  const cv::Mat mask = SquareMask();
  PerceptionFrame a = Counted(3, 1, 1, 5);  // P 3/4, R 3/4
  a.has_objects = true;
  a.object_hulls = {Square(1, 20, 20, 59, 59)};  // J 1
  const PerceptionFrame b = Counted(0, 4, 0, 5);  // P undefined, R 0, J 0 (no region)
  PerceptionFrame c = Counted(2, 0, 2, 0);        // P 1/2, R 1, J from the feature hull
  std::vector<MaskFrameScore> frames = {ScoreMaskFrame(&a, mask), ScoreMaskFrame(&b, mask),
                                        ScoreMaskFrame(&c, mask), ScoreMaskFrame(nullptr, mask)};
  const MaskSequenceScore s = SummarizeMaskSequence("synthetic", frames);
  EXPECT_EQ(s.frames, 4);
  EXPECT_EQ(s.frames_without_output, 1);
  EXPECT_EQ(s.frames_precision_undefined, 2);  // b and the frame without output
  EXPECT_EQ(s.frames_recall_undefined, 1);     // the frame without output
  EXPECT_DOUBLE_EQ(s.mean_precision, (0.75 + 0.5) / 2.0);
  EXPECT_DOUBLE_EQ(s.mean_recall, (0.75 + 0.0 + 1.0) / 3.0);
  EXPECT_NEAR(s.mean_iou, (1.0 + 0.0 + frames[2].iou + 0.0) / 4.0, 1e-12);
  EXPECT_EQ(s.pooled.true_positives, 5);
  EXPECT_EQ(s.pooled.false_positives, 3);
  EXPECT_EQ(s.pooled.false_negatives, 5);
  EXPECT_EQ(s.region_sources.at(RegionSource::kObjectHulls), 1);
  EXPECT_EQ(s.region_sources.at(RegionSource::kNone), 3);  // b; c (< 3 moving features per body); no output

  MaskSequenceScore other = s;
  other.mean_precision = NAN;
  other.mean_recall = 0.25;
  other.mean_iou = 0.5;
  const MaskDatasetScore d = SummarizeMaskDataset({s, other});
  EXPECT_EQ(d.sequences, 2);
  EXPECT_DOUBLE_EQ(d.mean_precision, s.mean_precision);  // NaN sequence skipped
  EXPECT_DOUBLE_EQ(d.mean_recall, (s.mean_recall + 0.25) / 2.0);
  EXPECT_DOUBLE_EQ(d.mean_iou, (s.mean_iou + 0.5) / 2.0);
}

TEST(RealDataScoring, CamVidClassFractions) {
  // Left half road, top-right quarter car, bottom-right quarter pedestrian, one void pixel.
  cv::Mat labels(100, 100, CV_8UC1, cv::Scalar(kCamVidRoad));
  labels(cv::Rect(50, 0, 50, 50)).setTo(kCamVidCar);
  labels(cv::Rect(50, 50, 50, 50)).setTo(kCamVidPedestrian);
  labels.at<uint8_t>(99, 0) = kCamVidVoid;
  // Moving: 1 on road, 6 on car, 2 on pedestrian, 1 on void = 10 -> 10 % on static, 80 % on movable.
  // Static-labelled: 19 on road, 4 on car, 0 on pedestrian. Unassigned: 1 on road.
  std::vector<std::tuple<double, double, int>> feats;
  feats.emplace_back(10, 10, 1);
  for (int i = 0; i < 6; ++i) feats.emplace_back(60 + i, 10, 1);
  for (int i = 0; i < 2; ++i) feats.emplace_back(60 + i, 70, 2);
  feats.emplace_back(0, 99, 1);
  for (int i = 0; i < 19; ++i) feats.emplace_back(10, 20 + i, 0);
  for (int i = 0; i < 4; ++i) feats.emplace_back(70 + i, 30, 0);
  feats.emplace_back(30, 30, -1);
  const PerceptionFrame f = FrameWith(feats);
  CamVidRunScore s;
  s.AddFrame(f, labels);
  s.Finish();
  EXPECT_EQ(s.features, 34);
  EXPECT_EQ(s.moving.moving, 10);
  EXPECT_DOUBLE_EQ(s.moving_on_static, 0.1);
  EXPECT_DOUBLE_EQ(s.moving_on_movable, 0.8);
  EXPECT_EQ(s.moving.on_void, 1);
  EXPECT_EQ(s.on_movable, 12);
  EXPECT_DOUBLE_EQ(s.movable_labelled_moving, 8.0 / 12.0);
  EXPECT_EQ(s.on_static, 21);
  EXPECT_DOUBLE_EQ(s.static_labelled_moving, 1.0 / 21.0);
  EXPECT_EQ(s.unassigned, 1);
  EXPECT_EQ(s.non_static.moving, 11);  // + the unassigned one on the road
  EXPECT_DOUBLE_EQ(s.non_static_on_static, 2.0 / 11.0);
  EXPECT_EQ(s.per_class.at(kCamVidCar), 10);
  EXPECT_EQ(s.moving_per_class.at(kCamVidCar), 6);
}

class TempDir {
 public:
  TempDir() {
    path_ = fs::temp_directory_path() / ("realdata_scoring_" + std::to_string(::getpid()) + "_" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

using testing_util::FeatureTrack;

mbslam::image_hull_t Hull(int body, float x0, float y0, float x1, float y1) {
  mbslam::image_hull_t h{};
  h.body_id = body;
  h.u = {x0, x1, x1, x0};
  h.v = {y0, y0, y1, y1};
  h.num_points = 4;
  return h;
}

TEST(RealDataScoring, LogToDavisSequenceScore) {
  TempDir tmp;
  // Two annotated frames (the same square mask) and a run log with tracks + objects for
  // frame 0 and tracks only for frame 1 (frame 2 has no output).
  DavisSequence seq;
  seq.name = "synthetic";
  for (int i = 0; i < 3; ++i) {
    const std::string p = (tmp.path() / ("0000" + std::to_string(i) + ".png")).string();
    ASSERT_TRUE(cv::imwrite(p, SquareMask()));
    seq.masks.push_back(p);
    seq.images.push_back(p);
  }
  const std::string log = (tmp.path() / "out.lcmlog").string();
  {
    Status st;
    auto w = LcmLogWriter::Open(log, &st);
    ASSERT_TRUE(w) << st.message();
    const ChannelOptions ch;
    mbslam::tracks_t t{};
    t.utime = 1000;
    t.frame_seq = 0;
    t.width = 100;
    t.height = 100;
    t.tracks = {FeatureTrack(1, 30, 30, 1), FeatureTrack(2, 40, 40, 1), FeatureTrack(3, 50, 50, 0), FeatureTrack(4, 80, 80, 1),
                FeatureTrack(5, 10, 10, 0), FeatureTrack(6, 45, 45, 0, 3, FT::FLAG_NEW), FeatureTrack(7, 35, 35, 0, 3, FT::FLAG_OCCLUDED),
                FeatureTrack(8, 90, 90, -1)};
    t.num_tracks = static_cast<int32_t>(t.tracks.size());
    t.hulls = {Hull(1, 30, 30, 80, 80)};
    t.num_hulls = 1;
    ASSERT_TRUE(w->Write(ch.perception_tracks, 1000, t).ok());
    mbslam::objects_t o{};
    o.utime = 1000;
    o.frame_seq = 0;
    mbslam::object_t obj{};
    obj.id = 1;
    obj.orientation[0] = 1.0;
    obj.hull = Hull(1, 20, 20, 59, 59);
    o.objects = {obj};
    o.num_objects = 1;
    ASSERT_TRUE(w->Write(ch.perception_objects, 1000, o).ok());
    t.utime = 2000;
    t.frame_seq = 1;
    t.tracks = {FeatureTrack(1, 30, 30, 1), FeatureTrack(2, 40, 40, 0)};
    t.num_tracks = 2;
    t.hulls = {Hull(1, 20, 20, 39, 59)};
    ASSERT_TRUE(w->Write(ch.perception_tracks, 2000, t).ok());
    w->Flush();
  }
  std::map<int64_t, PerceptionFrame> run;
  int bad = -1;
  ASSERT_TRUE(ReadPerceptionFrames(log, ChannelOptions(), &run, &bad).ok());
  EXPECT_EQ(bad, 0);
  ASSERT_EQ(run.size(), 2u);
  const PerceptionFrame& f0 = run.at(0);
  EXPECT_TRUE(f0.has_tracks);
  EXPECT_TRUE(f0.has_objects);
  EXPECT_EQ(f0.features.size(), 6u);  // new and occluded skipped
  EXPECT_EQ(f0.num_skipped, 2);
  EXPECT_EQ(f0.num_unassigned, 1);
  ASSERT_EQ(f0.object_hulls.size(), 1u);
  EXPECT_EQ(f0.object_hulls[0].body_id, 1);
  EXPECT_FALSE(run.at(1).has_objects);

  MaskSequenceScore s;
  ASSERT_TRUE(ScoreDavisSequence(seq, run, &s).ok());
  ASSERT_EQ(s.per_frame.size(), 3u);
  // Frame 0: moving 30,30 / 40,40 inside, 80,80 outside; static 50,50 inside -> P 2/3, R 2/3;
  // region = the object's hull = the mask -> J 1.
  EXPECT_DOUBLE_EQ(s.per_frame[0].precision, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.per_frame[0].recall, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.per_frame[0].iou, 1.0);
  // Frame 1: P 1, R 1/2, region = the tracks message's hull (half the mask) -> J 0.5.
  EXPECT_EQ(s.per_frame[1].region_source, RegionSource::kTrackHulls);
  EXPECT_DOUBLE_EQ(s.per_frame[1].precision, 1.0);
  EXPECT_DOUBLE_EQ(s.per_frame[1].recall, 0.5);
  EXPECT_DOUBLE_EQ(s.per_frame[1].iou, 0.5);
  // Frame 2: no output.
  EXPECT_FALSE(s.per_frame[2].has_output);
  EXPECT_DOUBLE_EQ(s.per_frame[2].iou, 0.0);
  EXPECT_EQ(s.frames_without_output, 1);
  EXPECT_EQ(s.frames_precision_undefined, 1);
  EXPECT_DOUBLE_EQ(s.mean_iou, 0.5);
  EXPECT_DOUBLE_EQ(s.mean_precision, (2.0 / 3.0 + 1.0) / 2.0);

  // A run whose images have another size is refused.
  run.at(1).width = 200;
  EXPECT_FALSE(ScoreDavisSequence(seq, run, &s).ok());
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
