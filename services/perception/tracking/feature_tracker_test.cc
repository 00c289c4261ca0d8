#include "services/perception/tracking/feature_tracker.h"

#include <gtest/gtest.h>

#include <map>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "services/perception/tracking/patch_matcher.h"

namespace mbslam {
namespace {

cv::Mat Texture(int w, int h, int seed) {
  cv::RNG rng(seed);
  cv::Mat noise(h, w, CV_8UC1);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::Mat fine, coarse, out;
  cv::GaussianBlur(noise, fine, cv::Size(0, 0), 1.5);
  cv::GaussianBlur(noise, coarse, cv::Size(0, 0), 5.0);
  cv::addWeighted(fine, 1.0, coarse, 2.0, -128, out);
  return out;
}

cv::Mat Shift(const cv::Mat& img, float dx, float dy) {
  cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::Mat out;
  cv::warpAffine(img, out, m, img.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return out;
}

std::vector<cv::Mat> Pyramid(const cv::Mat& img) {
  std::vector<cv::Mat> p;
  cv::buildOpticalFlowPyramid(img, p, cv::Size(21, 21), 3);
  return p;
}

TEST(FeatureTracker, DetectsSpreadFeaturesUpToTheLimit) {
  TrackerOptions o;
  o.max_features = 500;
  FeatureTracker tracker(o);
  tracker.TrackFrame(Pyramid(Texture(640, 480, 1)), 0, {});
  const auto& tracks = tracker.tracks();
  EXPECT_GT(tracks.size(), 400u);
  EXPECT_LE(tracks.size(), 500u);
  std::set<int> cells;
  for (const Track& t : tracks) {
    cells.insert(static_cast<int>(t.uv.x() / 40) + 100 * static_cast<int>(t.uv.y() / 40));
  }
  EXPECT_GT(cells.size(), 16u * 12u * 9u / 10u) << "features cover >= 90% of the grid";
  for (size_t i = 0; i < tracks.size(); ++i) {
    for (size_t j = i + 1; j < tracks.size(); ++j) {
      ASSERT_GE((tracks[i].uv - tracks[j].uv).norm(), o.min_distance_px - 1.0);
    }
  }
}

TEST(FeatureTracker, FollowsAKnownShiftToSubpixelAccuracy) {
  FeatureTracker tracker(TrackerOptions{});
  const cv::Mat base = Texture(640, 480, 2);
  tracker.TrackFrame(Pyramid(base), 0, {});
  std::map<int64_t, Eigen::Vector2f> start;
  for (const Track& t : tracker.tracks()) start[t.id] = t.uv;
  const float dx = 6.3f, dy = -2.7f;  // warpAffine moves content by (+dx, +dy)
  tracker.TrackFrame(Pyramid(Shift(base, dx, dy)), 1, {});
  int checked = 0;
  double max_err = 0.0;
  for (const Track& t : tracker.tracks()) {
    if (t.is_new) continue;
    ASSERT_TRUE(start.count(t.id));
    const Eigen::Vector2f expected = start[t.id] + Eigen::Vector2f(dx, dy);
    max_err = std::max<double>(max_err, (t.uv - expected).norm());
    ++checked;
  }
  EXPECT_GT(checked, 800);
  EXPECT_LT(max_err, 0.25);
  EXPECT_GT(tracker.stats().created, 0) << "new features fill the uncovered border strip";
}

TEST(FeatureTracker, OccludedTracksAreKeptAndRecovered) {
  TrackerOptions o;
  FeatureTracker tracker(o);
  const cv::Mat base = Texture(640, 480, 3);
  for (int f = 0; f < 3; ++f) tracker.TrackFrame(Pyramid(base), f, {});
  for (Track& t : tracker.tracks()) t.body_id = 0;
  // A moving object covers the centre for three frames (its own pixels are a flat
  // grey box, so the background there is invisible).
  const std::vector<Eigen::Vector2f> hull = {{250, 180}, {390, 180}, {390, 300}, {250, 300}};
  std::map<int64_t, Eigen::Vector2f> inside;
  for (const Track& t : tracker.tracks()) {
    if (InsideConvexHull(hull, t.uv)) inside[t.id] = t.uv;
  }
  ASSERT_GT(inside.size(), 20u);
  TrackingHints hints;
  hints.occluders.push_back({7, hull});
  cv::Mat covered = base.clone();
  cv::rectangle(covered, cv::Rect(245, 175, 150, 130), cv::Scalar(128), -1);
  for (int f = 3; f <= 5; ++f) {
    tracker.TrackFrame(Pyramid(covered), f, hints);
    int occluded = 0;
    for (const Track& t : tracker.tracks()) occluded += inside.count(t.id) && !t.active();
    EXPECT_EQ(occluded, static_cast<int>(inside.size())) << "frame " << f;
  }
  tracker.TrackFrame(Pyramid(base), 6, {});
  int recovered = 0;
  for (const Track& t : tracker.tracks()) {
    if (inside.count(t.id) && t.active()) {
      ++recovered;
      EXPECT_LT((t.uv - inside[t.id]).norm(), 0.5);
    }
  }
  EXPECT_GE(recovered, static_cast<int>(0.8 * inside.size()));
}

TEST(FeatureTracker, InconsistentMatchesAreDropped) {
  FeatureTracker tracker(TrackerOptions{});
  tracker.TrackFrame(Pyramid(Texture(320, 240, 4)), 0, {});
  const size_t before = tracker.tracks().size();
  // A completely different image: forward-backward checks must reject nearly all.
  tracker.TrackFrame(Pyramid(Texture(320, 240, 99)), 1, {});
  int survivors = 0;
  for (const Track& t : tracker.tracks()) survivors += !t.is_new;
  EXPECT_LT(survivors, static_cast<int>(before / 10)) << "of " << before;
}

// A glitch image (here an unrelated one) between good images: rejected, the tracks kept
// as they were, and the next image tracked from the last good one. Two in a row are a real
// change of view: the second is taken.
TEST(FeatureTracker, GlitchImageIsRejectedAndTracksSurviveIt) {
  FeatureTracker tracker(TrackerOptions{});
  const cv::Mat base = Texture(320, 240, 5);
  for (int f = 0; f < 4; ++f) tracker.TrackFrame(Pyramid(Shift(base, f, 0)), f, {});
  EXPECT_FALSE(tracker.stats().rejected);
  std::map<int64_t, Eigen::Vector2f> before;
  for (const Track& t : tracker.tracks()) before[t.id] = t.uv;
  ASSERT_GT(before.size(), 100u);
  tracker.TrackFrame(Pyramid(Texture(320, 240, 77)), 4, {});
  EXPECT_TRUE(tracker.stats().rejected);
  EXPECT_GE(tracker.stats().established, 100);
  ASSERT_EQ(tracker.tracks().size(), before.size());
  for (const Track& t : tracker.tracks()) {
    ASSERT_TRUE(before.count(t.id));
    EXPECT_EQ(t.uv, before[t.id]) << "a rejected image changes no track";
  }
  // The next good image (two steps on from the last good one) is tracked from it.
  tracker.TrackFrame(Pyramid(Shift(base, 5, 0)), 5, {});
  EXPECT_FALSE(tracker.stats().rejected);
  int followed = 0;
  for (const Track& t : tracker.tracks()) {
    auto it = before.find(t.id);
    if (it != before.end() && std::abs(t.uv.x() - it->second.x() - 2.0f) < 0.3f) ++followed;
  }
  EXPECT_GT(followed, static_cast<int>(0.8 * before.size()));
  // Two unrelated images in a row: the first is rejected, the second taken.
  for (int f = 6; f < 9; ++f) tracker.TrackFrame(Pyramid(Shift(base, f, 0)), f, {});
  tracker.TrackFrame(Pyramid(Texture(320, 240, 78)), 9, {});
  EXPECT_TRUE(tracker.stats().rejected);
  tracker.TrackFrame(Pyramid(Texture(320, 240, 79)), 10, {});
  EXPECT_FALSE(tracker.stats().rejected);
  // Off: never rejected.
  TrackerOptions off;
  off.glitch_max_survival = 0.0;
  FeatureTracker plain(off);
  for (int f = 0; f < 4; ++f) plain.TrackFrame(Pyramid(Shift(base, f, 0)), f, {});
  plain.TrackFrame(Pyramid(Texture(320, 240, 77)), 4, {});
  EXPECT_FALSE(plain.stats().rejected);
}

// Fast image motion switches KLT to its wider window and extra level for the next image,
// and back when the motion slows down.
TEST(FeatureTracker, FastMotionSwitchesToWiderKlt) {
  FeatureTracker tracker(TrackerOptions{});
  const cv::Mat base = Texture(320, 240, 6);
  tracker.TrackFrame(Pyramid(base), 0, {});
  tracker.TrackFrame(Pyramid(Shift(base, 14, 0)), 1, {});
  EXPECT_FALSE(tracker.stats().fast_motion) << "the first motion is not known yet";
  EXPECT_NEAR(tracker.stats().median_flow_px, 14.0, 0.5);
  tracker.TrackFrame(Pyramid(Shift(base, 28, 0)), 2, {});
  EXPECT_TRUE(tracker.stats().fast_motion);
  tracker.TrackFrame(Pyramid(Shift(base, 29, 0)), 3, {});
  EXPECT_TRUE(tracker.stats().fast_motion);
  EXPECT_NEAR(tracker.stats().median_flow_px, 1.0, 0.3);
  tracker.TrackFrame(Pyramid(Shift(base, 30, 0)), 4, {});
  EXPECT_FALSE(tracker.stats().fast_motion);
  TrackerOptions off;
  off.klt_fast_flow_px = 0.0;
  FeatureTracker plain(off);
  for (int f = 0; f < 3; ++f) plain.TrackFrame(Pyramid(Shift(base, 14 * f, 0)), f, {});
  EXPECT_FALSE(plain.stats().fast_motion);
}

TEST(FeatureTracker, GuidedMatchRecoversLostTracksNearPrediction) {
  FeatureTracker tracker(TrackerOptions{});
  const cv::Mat base = Texture(640, 480, 5);
  tracker.TrackFrame(Pyramid(base), 0, {});
  // A large jump that KLT with a wrong prediction will miss for some tracks.
  std::map<int64_t, Eigen::Vector2f> start;
  TrackingHints wrong;
  for (const Track& t : tracker.tracks()) {
    start[t.id] = t.uv;
    wrong.predicted_uv[t.id] = t.uv + Eigen::Vector2f(-40, 0);
  }
  const cv::Mat moved = Shift(base, 45, 0);
  tracker.TrackFrame(Pyramid(moved), 1, wrong);
  std::unordered_map<int64_t, Eigen::Vector2f> good;
  for (const auto& [id, uv] : start) good[id] = uv + Eigen::Vector2f(44, 1);
  tracker.GuidedMatch(good);
  int right = 0;
  for (const Track& t : tracker.tracks()) {
    if (!start.count(t.id)) continue;
    if ((t.uv - (start[t.id] + Eigen::Vector2f(45, 0))).norm() < 0.5) ++right;
  }
  EXPECT_GT(right, static_cast<int>(0.7 * start.size()));
}

TEST(ConvexHull, HullAndInside) {
  std::vector<Eigen::Vector2f> pts = {{0, 0}, {4, 0}, {4, 4}, {0, 4}, {2, 2}, {1, 3}};
  const auto hull = ConvexHull(pts);
  EXPECT_EQ(hull.size(), 4u);
  EXPECT_TRUE(InsideConvexHull(hull, {2, 1}));
  EXPECT_FALSE(InsideConvexHull(hull, {5, 1}));
}

TEST(PatchMatcher, FindsShiftedPatch) {
  const cv::Mat base = Texture(200, 200, 6);
  cv::Mat patch;
  ASSERT_TRUE(ExtractPatch(base, {100.0f, 90.0f}, 11, &patch));
  const cv::Mat moved = Shift(base, 3.4f, -1.6f);
  const PatchMatch m = FindPatchZssd(moved, patch, {101.0f, 90.0f}, 8);
  ASSERT_TRUE(m.found);
  EXPECT_LT((m.uv - Eigen::Vector2f(103.4f, 88.4f)).norm(), 0.35);
}

}  // namespace
}  // namespace mbslam
