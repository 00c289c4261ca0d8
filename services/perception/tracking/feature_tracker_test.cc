#include "services/perception/tracking/feature_tracker.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <algorithm>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "services/perception/tracking/disc_stamp.h"
#include "services/perception/tracking/patch_matcher.h"
#include "services/perception/tracking/test_images.h"

namespace mbslam {
namespace {

using testing_images::Shift;
using testing_images::Texture;

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

TEST(FeatureTracker, MovingHullsGetDenserFeaturesAboveTheLimit) {
  // Two moving objects: a narrow one (30 x 90 px, a person 9 m away), which the grid
  // gives about as many features as the background around it, and a larger one the grid
  // already covers with more than object_features.
  const std::vector<Eigen::Vector2f> narrow = {{300, 200}, {330, 200}, {330, 290}, {300, 290}};
  const std::vector<Eigen::Vector2f> wide = {{60, 60}, {220, 60}, {220, 160}, {60, 160}};
  TrackingHints hints;
  hints.occluders.push_back({3, narrow});
  hints.occluders.push_back({4, wide});
  const cv::Mat base = Texture(640, 480, 11);
  auto run = [&](const TrackerOptions& o) {
    auto tracker = std::make_unique<FeatureTracker>(o);
    tracker->TrackFrame(Pyramid(base), 0, {});
    tracker->TrackFrame(Pyramid(base), 1, hints);
    return tracker;
  };
  auto inside = [](const FeatureTracker& t, const std::vector<Eigen::Vector2f>& hull) {
    int n = 0;
    for (const Track& tr : t.tracks()) n += InsideConvexHull(hull, tr.uv);
    return n;
  };
  const auto plain = run(TrackerOptions{});
  const int plain_narrow = inside(*plain, narrow), plain_wide = inside(*plain, wide);
  EXPECT_LT(plain_narrow, 20);
  EXPECT_GT(plain_wide, 40);
  EXPECT_EQ(plain->stats().created_on_objects, 0);

  TrackerOptions o;
  o.object_features = 40;
  o.object_max_hull_share = 1.0;  // any hull (the wide one is 5.2 % of the image)
  const auto dense = run(o);
  const FeatureTracker& t = *dense;
  EXPECT_EQ(inside(t, narrow), 40);
  EXPECT_EQ(inside(t, wide), plain_wide) << "already holds more than object_features";
  int on_objects = 0;
  for (const Track& tr : t.tracks()) {
    if (!tr.on_object) continue;
    ++on_objects;
    ASSERT_TRUE(InsideConvexHull(narrow, tr.uv));
    const float to_edge = std::min({tr.uv.x() - narrow[0].x(), narrow[1].x() - tr.uv.x(), tr.uv.y() - narrow[0].y(),
                                    narrow[2].y() - tr.uv.y()});
    EXPECT_GE(to_edge, o.object_hull_margin_px);
    for (const Track& other : t.tracks()) {
      if (other.id == tr.id) continue;
      ASSERT_GE((other.uv - tr.uv).norm(), o.object_min_distance_px);
    }
  }
  EXPECT_EQ(on_objects, 40 - plain_narrow);
  EXPECT_EQ(t.stats().created_on_objects, on_objects);
  // The background keeps its share: the tracks not added on objects are those without.
  EXPECT_EQ(static_cast<int>(t.tracks().size()) - on_objects, static_cast<int>(plain->tracks().size()));
  // The next image: the object's tracks are kept and none is added.
  dense->TrackFrame(Pyramid(base), 2, hints);
  EXPECT_EQ(dense->stats().created_on_objects, 0);
  EXPECT_EQ(inside(*dense, narrow), 40);
  // Once the segmentation puts them in the static world they are ordinary tracks: with
  // them the tracks are above max_features, so no new one is detected until some are lost.
  for (Track& tr : dense->tracks()) tr.body_id = 0;
  dense->TrackFrame(Pyramid(base), 3, {});
  for (const Track& tr : dense->tracks()) EXPECT_FALSE(tr.on_object);
  EXPECT_GT(dense->tracks().size(), static_cast<size_t>(o.max_features));
  EXPECT_EQ(dense->stats().created, 0);

  // The budget above max_features bounds them, whatever the hulls want.
  o.object_extra_features = 10;
  const auto bounded = run(o);
  EXPECT_EQ(bounded->stats().created_on_objects, 10);
  EXPECT_EQ(inside(*bounded, narrow), plain_narrow + 10);

  // Hulls larger than object_max_hull_share of the image get none, however few tracks
  // they hold (the narrow one is 0.9 % of the image, the wide one 5.2 %).
  TrackerOptions many;
  many.object_features = 150;
  many.object_max_hull_share = 0.04;
  const auto shared = run(many);
  EXPECT_EQ(inside(*shared, wide), plain_wide);
  EXPECT_GT(inside(*shared, narrow), 40);

  // Nor do objects younger than object_min_age_frames (the hulls here are 2 images old).
  hints.occluders[0].age_frames = hints.occluders[1].age_frames = 2;
  o.object_extra_features = 200;
  o.object_min_age_frames = 3;
  EXPECT_EQ(run(o)->stats().created_on_objects, 0);
  o.object_min_age_frames = 2;
  EXPECT_EQ(run(o)->stats().created_on_objects, 40 - plain_narrow);
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

// An exposure step (a camera's automatic exposure, a rendered sequence's) breaks KLT's
// constant brightness: without the compensation most tracks are matched off target
// (a larger step makes the image look like a glitch). With it the step is undone (mean and contrast mapped onto the previous
// image's) and the tracks follow the image's motion; the next image, back at the old
// exposure, is tracked from the corrected one.
TEST(FeatureTracker, ExposureStepIsUndoneInsteadOfRejected) {
  // Texture on shading that varies across the image, as in a real scene (the step is
  // measured on how the patches' mean grey levels map).
  cv::Mat shading(240, 320, CV_8UC1), base;
  for (int r = 0; r < shading.rows; ++r) {
    for (int c = 0; c < shading.cols; ++c) shading.at<uint8_t>(r, c) = static_cast<uint8_t>(70 + 50 * std::sin(0.02 * c) * std::cos(0.015 * r));
  }
  cv::addWeighted(Texture(320, 240, 5), 0.4, shading, 1.0, 0.0, base);
  // A step KLT survives off target, and one it does not survive (the whole images
  // measure that one).
  for (const auto& [step_gain, step_offset] : {std::pair{0.7, 60.0}, std::pair{0.4, 130.0}})
  for (bool retry : {false, true}) {
    SCOPED_TRACE(std::string(retry ? "retry" : "no retry") + ", gain " + std::to_string(step_gain));
    auto exposed = [&](const cv::Mat& img) {
      cv::Mat out;
      img.convertTo(out, CV_8U, step_gain, step_offset);
      return out;
    };
    TrackerOptions options;
    options.exposure_compensation = retry;
    FeatureTracker tracker(options);
    for (int f = 0; f < 4; ++f) tracker.TrackFrame(Pyramid(Shift(base, f, 0)), f, {});
    std::map<int64_t, Eigen::Vector2f> before;
    for (const Track& t : tracker.tracks()) before[t.id] = t.uv;
    ASSERT_GT(before.size(), 100u);
    tracker.TrackFrame(Pyramid(exposed(Shift(base, 4, 0))), 4, {});
    const TrackerStats& s = tracker.stats();
    int followed = 0;
    for (const Track& t : tracker.tracks()) {
      auto it = before.find(t.id);
      if (it != before.end() && std::abs(t.uv.x() - it->second.x() - 1.0f) < 0.3f &&
          std::abs(t.uv.y() - it->second.y()) < 0.3f) {
        ++followed;
      }
    }
    if (!retry) {
      // Off target, or lost and the image rejected as a glitch.
      EXPECT_FALSE(s.exposure_corrected);
      EXPECT_LT(followed, static_cast<int>(0.3 * before.size()));
      if (step_gain < 0.5) {
        EXPECT_TRUE(s.rejected);
      }
      std::cerr << "without compensation, gain " << step_gain << ": rejected " << s.rejected << ", "
                << s.established_matched << " of " << s.established << " matched, " << followed << " on target\n";
      continue;
    }
    EXPECT_FALSE(s.rejected);
    EXPECT_TRUE(s.exposure_corrected);
    EXPECT_NEAR(s.exposure_gain, 1.0 / step_gain, 0.05 / step_gain);
    EXPECT_NEAR(s.exposure_offset, -step_offset / step_gain, 5.0 / step_gain);
    EXPECT_GT(followed, static_cast<int>(0.8 * before.size()));
    // Back to the old exposure: tracked from the corrected image, no retry needed.
    tracker.TrackFrame(Pyramid(Shift(base, 5, 0)), 5, {});
    EXPECT_FALSE(tracker.stats().rejected);
    EXPECT_FALSE(tracker.stats().exposure_corrected);
    EXPECT_GT(tracker.stats().tracked, static_cast<int>(0.8 * before.size()));
  }
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

// DiscStamp sets exactly cv::circle's filled disc: radii 0-20, centres inside, on and
// beyond every edge of the mask.
TEST(DiscStamp, SameAsFilledCvCircle) {
  cv::RNG rng(5);
  for (int radius = 0; radius <= 20; ++radius) {
    const DiscStamp disc(radius);
    for (int k = 0; k < 200; ++k) {
      const cv::Point c(rng.uniform(-30, 91), rng.uniform(-30, 71));
      cv::Mat got(40, 60, CV_8UC1, cv::Scalar(255)), want = got.clone();
      disc.Stamp(&got, c, 0);
      cv::circle(want, c, radius, cv::Scalar(0), cv::FILLED);
      ASSERT_EQ(cv::countNonZero(got != want), 0) << "radius " << radius << " centre " << c;
    }
  }
}

// ExtractPatch gives cv::getRectSubPix's bytes: random sub-pixel centres, integer and
// half-pixel ones, and centres against every image edge (the last column / row read
// at zero weight goes through OpenCV's own border).
TEST(PatchMatcher, ExtractPatchIsGetRectSubPixBitForBit) {
  cv::RNG rng(3);
  cv::Mat image(120, 160, CV_8UC1);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  image(cv::Rect(20, 20, 30, 30)).setTo(255);  // saturated weights' sum
  for (int size : {5, 11, 15}) {
    const float half = 0.5f * static_cast<float>(size - 1);
    std::vector<Eigen::Vector2f> centres = {{half, half},
                                            {159.0f - half, 119.0f - half},
                                            {159.0f - half - 0.25f, 60.0f},
                                            {80.0f, 119.0f - half - 0.5f},
                                            {35.0f, 35.0f},
                                            {35.5f, 35.25f}};
    for (int k = 0; k < 3000; ++k) {
      Eigen::Vector2f c(rng.uniform(half, 159.0f - half), rng.uniform(half, 119.0f - half));
      if (k % 5 == 0) c.x() = std::floor(c.x()) + 0.5f;
      if (k % 7 == 0) c.y() = std::floor(c.y());
      centres.push_back(c);
    }
    for (const Eigen::Vector2f& c : centres) {
      cv::Mat got, want;
      ASSERT_TRUE(ExtractPatch(image, c, size, &got)) << c.transpose();
      cv::getRectSubPix(image, cv::Size(size, size), cv::Point2f(c.x(), c.y()), want, CV_8U);
      ASSERT_EQ(got.type(), CV_8UC1);
      ASSERT_EQ(cv::countNonZero(got != want), 0) << "size " << size << " at " << c.transpose();
    }
    cv::Mat none;
    EXPECT_FALSE(ExtractPatch(image, {half - 0.01f, 50.0f}, size, &none));
    EXPECT_FALSE(ExtractPatch(image, {50.0f, 119.0f - half + 0.01f}, size, &none));
  }
}

TEST(PatchMatcher, CornerRatioTellsCornersFromEdges) {
  // A corner (two perpendicular edges), a blurred edge at 30 deg (as a camera sees one),
  // a flat patch, a textured one.
  cv::Mat corner(11, 11, CV_8UC1, cv::Scalar(40)), edge(11, 11, CV_8UC1);
  corner(cv::Rect(5, 5, 6, 6)).setTo(200);
  for (int y = 0; y < 11; ++y) {
    for (int x = 0; x < 11; ++x) {
      const double d = (x - 5) * 0.5 - (y - 5) * 0.866;  // signed distance to the edge (px)
      edge.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(120.0 + 80.0 * std::tanh(d));
    }
  }
  const cv::Mat flat(11, 11, CV_8UC1, cv::Scalar(90));
  cv::Mat textured;
  ASSERT_TRUE(ExtractPatch(Texture(60, 60, 3), {30.0f, 30.0f}, 11, &textured));
  EXPECT_GT(PatchCornerRatio(corner), 0.3);
  EXPECT_LT(PatchCornerRatio(edge), 0.05);
  EXPECT_EQ(PatchCornerRatio(flat), 0.0);
  EXPECT_GT(PatchCornerRatio(textured), 0.1);
  EXPECT_EQ(PatchCornerRatio(cv::Mat()), 0.0);
  // Invariant to contrast and to the patch's type.
  cv::Mat scaled, as_float;
  corner.convertTo(scaled, CV_8U, 0.5, 10.0);
  corner.convertTo(as_float, CV_32F);
  EXPECT_NEAR(PatchCornerRatio(scaled), PatchCornerRatio(corner), 1e-2);
  EXPECT_NEAR(PatchCornerRatio(as_float), PatchCornerRatio(corner), 1e-12);
  // Known values: f = x^2 + y^2 has an isotropic tensor (1), f = x^2 + 2 y^2 has its
  // eigenvalues in the ratio 1 : 4 (central differences are exact on quadratics).
  cv::Mat iso(11, 11, CV_64F), aniso(11, 11, CV_64F);
  for (int y = 0; y < 11; ++y) {
    for (int x = 0; x < 11; ++x) {
      iso.at<double>(y, x) = (x - 5) * (x - 5) + (y - 5) * (y - 5);
      aniso.at<double>(y, x) = (x - 5) * (x - 5) + 2.0 * (y - 5) * (y - 5);
    }
  }
  EXPECT_NEAR(PatchCornerRatio(iso), 1.0, 1e-12);
  EXPECT_NEAR(PatchCornerRatio(aniso), 0.25, 1e-12);
  // Rotation by 90 deg and a corner in the outer ring change nothing / still count.
  cv::Mat rotated;
  cv::rotate(corner, rotated, cv::ROTATE_90_CLOCKWISE);
  EXPECT_NEAR(PatchCornerRatio(rotated), PatchCornerRatio(corner), 1e-12);
  cv::Mat rim(11, 11, CV_8UC1, cv::Scalar(40));
  rim(cv::Rect(0, 0, 2, 2)).setTo(200);
  EXPECT_GT(PatchCornerRatio(rim), 0.3);
  // Not a grey patch, or not finite: no evidence of a corner.
  cv::Mat colour(11, 11, CV_8UC3, cv::Scalar(40, 40, 40));
  colour(cv::Rect(0, 0, 6, 6)).setTo(cv::Scalar(200, 200, 200));
  EXPECT_EQ(PatchCornerRatio(colour), 0.0);
  cv::Mat with_inf = iso.clone();
  with_inf.at<double>(5, 5) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(PatchCornerRatio(with_inf), 0.0);
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

namespace mbslam {
namespace {

// image2(c + A (x - c)) = image1(x): an affine view change about c.
cv::Mat AffineView(const cv::Mat& img, const Eigen::Matrix2f& A, const Eigen::Vector2f& c) {
  const Eigen::Vector2f t = c - A * c;
  cv::Mat m = (cv::Mat_<double>(2, 3) << A(0, 0), A(0, 1), t.x(), A(1, 0), A(1, 1), t.y());
  cv::Mat out;
  cv::warpAffine(img, out, m, img.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return out;
}

TEST(PatchMatcher, AlignPatchFindsSubpixelShiftWithGainAndBias) {
  const cv::Mat img = Texture(200, 200, 5);
  cv::Mat templ;
  cv::getRectSubPix(img, cv::Size(13, 13), cv::Point2f(100.3f, 90.6f), templ, CV_32F);
  templ = templ * 0.7 + 20.0;  // another exposure
  const PatchAlignment al = AlignPatch(img, templ, Eigen::Vector2f(101.5f, 89.5f));
  ASSERT_TRUE(al.converged);
  EXPECT_LT((al.uv - Eigen::Vector2f(100.3f, 90.6f)).norm(), 0.03f);
  EXPECT_GT(al.ncc, 0.99f);
  // A flat template cannot be aligned.
  const PatchAlignment flat = AlignPatch(img, cv::Mat(13, 13, CV_32F, cv::Scalar(50.0f)), Eigen::Vector2f(100, 90));
  EXPECT_FALSE(flat.converged);
}

float FloatNcc(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat r;
  cv::matchTemplate(a, b, r, cv::TM_CCOEFF_NORMED);
  return r.at<float>(0, 0);
}

TEST(PatchMatcher, WarpedReferenceMatchesTheNewView) {
  const cv::Mat img = Texture(320, 320, 6);
  const Eigen::Matrix2f A = (Eigen::Matrix2f() << 1.3f, 0.1f, -0.05f, 1.7f).finished();
  const Eigen::Vector2f c(160.0f, 160.0f);
  const cv::Mat view = AffineView(img, A, c);
  const Eigen::Vector2f p(150.0f, 170.0f);
  const Eigen::Vector2f q = c + A * (p - c);
  cv::Mat reference, templ, seen;
  cv::getRectSubPix(img, cv::Size(31, 31), cv::Point2f(p.x(), p.y()), reference, CV_32F);
  ASSERT_TRUE(WarpReferencePatch(reference, A, 13, &templ));
  cv::getRectSubPix(view, cv::Size(13, 13), cv::Point2f(q.x(), q.y()), seen, CV_32F);
  const cv::Mat unwarped = reference(cv::Rect(9, 9, 13, 13)).clone();
  EXPECT_GT(FloatNcc(seen, templ), 0.98f);
  EXPECT_LT(FloatNcc(seen, unwarped), FloatNcc(seen, templ) - 0.1f);
  // A shrinking view needs samples beyond the reference: refused.
  EXPECT_FALSE(WarpReferencePatch(reference, 0.3f * Eigen::Matrix2f::Identity(), 13, &templ));
}

TEST(FeatureTracker, DriftedTracksAreRealignedOnTheirWarpedReference) {
  TrackerOptions o;
  o.max_features = 300;
  o.warp_align_max_px = 2.0;  // the drift below is 1.2 px
  FeatureTracker tracker(o);
  const cv::Mat img = Texture(640, 480, 7);
  tracker.TrackFrame(Pyramid(img), 0, {});
  std::vector<std::pair<int64_t, int64_t>> keys;
  std::map<int64_t, Eigen::Vector2f> first;
  for (const Track& t : tracker.tracks()) {
    keys.emplace_back(t.id, 42);
    first[t.id] = t.uv;
  }
  EXPECT_GT(tracker.SetWarpReferences(keys), static_cast<int>(keys.size()) * 9 / 10) << "nearly all away from the border";
  // The next view: a ground-like stretch, twice as strong vertically.
  const Eigen::Matrix2f A = (Eigen::Matrix2f() << 1.2f, 0.0f, 0.05f, 1.45f).finished();
  const Eigen::Vector2f c(320.0f, 240.0f);
  TrackingHints hints;
  for (const auto& [id, uv] : first) hints.predicted_uv[id] = c + A * (uv - c);
  tracker.TrackFrame(Pyramid(AffineView(img, A, c)), 1, hints);
  // Drift every surviving old track by 1.2 px, then re-align with the true warp and, for
  // contrast, with no warp at all.
  const Eigen::Vector2f drift(0.9f, -0.8f);
  std::vector<WarpedReference> warps, none;
  std::map<int64_t, Eigen::Vector2f> truth;
  for (Track& t : tracker.tracks()) {
    auto it = first.find(t.id);
    if (it == first.end() || !t.active() || t.last_seen_frame != 1) continue;
    truth[t.id] = c + A * (it->second - c);
    t.uv = truth[t.id] + drift;
    warps.push_back({t.id, A});
    none.push_back({t.id, Eigen::Matrix2f::Identity()});
  }
  ASSERT_GT(truth.size(), 100u);
  std::vector<Track> saved = tracker.tracks();
  const WarpAlignStats stats = tracker.AlignToReferences(warps);
  EXPECT_GE(stats.tried, static_cast<int>(truth.size()) * 95 / 100);
  EXPECT_GT(stats.corrected, 0.9 * stats.tried);
  EXPECT_NEAR(stats.mean_correction_px, drift.norm(), 0.1);
  auto error_quantile = [&](double q) {
    std::vector<float> errors;
    for (const Track& t : tracker.tracks()) {
      if (truth.count(t.id)) errors.push_back((t.uv - truth[t.id]).norm());
    }
    std::sort(errors.begin(), errors.end());
    return errors[static_cast<size_t>(q * static_cast<double>(errors.size() - 1))];
  };
  const float warped_median = error_quantile(0.5);
  EXPECT_LT(warped_median, 0.05f);
  EXPECT_LT(error_quantile(0.9), 0.15f);
  // Without the warp the reference does not fit the stretched view: the alignment lands
  // off the true position.
  tracker.tracks() = saved;
  tracker.AlignToReferences(none);
  EXPECT_GT(error_quantile(0.5), 3.0f * warped_median);
  // Corrections beyond warp_align_max_px are refused.
  TrackerOptions strict = o;
  strict.warp_align_max_px = 0.5;
  FeatureTracker strict_tracker(strict);
  strict_tracker.TrackFrame(Pyramid(img), 0, {});
  strict_tracker.SetWarpReferences(keys);
  strict_tracker.TrackFrame(Pyramid(AffineView(img, A, c)), 1, hints);
  std::vector<WarpedReference> strict_warps;
  for (Track& t : strict_tracker.tracks()) {
    auto it = first.find(t.id);
    if (it == first.end() || !t.active() || t.last_seen_frame != 1) continue;
    t.uv = c + A * (it->second - c) + drift;
    strict_warps.push_back({t.id, A});
  }
  const WarpAlignStats strict_stats = strict_tracker.AlignToReferences(strict_warps);
  EXPECT_GT(strict_stats.tried, 100);
  EXPECT_EQ(strict_stats.corrected, 0);
  EXPECT_EQ(strict_stats.refused, strict_stats.tried);
  // A warp beyond warp_max_scale is not used.
  tracker.tracks() = saved;
  std::vector<WarpedReference> huge;
  for (const WarpedReference& w : warps) huge.push_back({w.track_id, 3.0f * Eigen::Matrix2f::Identity()});
  EXPECT_EQ(tracker.AlignToReferences(huge).tried, 0);
}

}  // namespace
}  // namespace mbslam

namespace mbslam {
namespace {

// A wide-baseline view turned by 25 deg: KLT loses most tracks and the ORB fallback
// re-finds them. The lost tracks' descriptors must be oriented as the new image's
// keypoints are (tracking.fallback_orientation): unoriented, few of them match.
int RefoundWithinPx(bool oriented, double max_err_px, int* matched) {
  TrackerOptions o;
  o.fallback_orientation = oriented;
  FeatureTracker tracker(o);
  const cv::Mat base = testing_images::Texture(640, 480, 9);
  tracker.TrackFrame(Pyramid(base), 0, {});
  std::map<int64_t, Eigen::Vector2f> start;
  for (const Track& t : tracker.tracks()) start[t.id] = t.uv;
  const cv::Point2f centre(319.5f, 239.5f);
  const cv::Mat rot = cv::getRotationMatrix2D(centre, 25.0, 1.0);
  cv::Mat turned;
  cv::warpAffine(base, turned, rot, base.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  tracker.TrackFrame(Pyramid(turned), 1, {});
  *matched = tracker.stats().descriptor_matched;
  int good = 0;
  for (const Track& t : tracker.tracks()) {
    auto it = start.find(t.id);
    if (it == start.end() || t.last_seen_frame != 1) continue;
    const Eigen::Vector2f p = it->second;
    const Eigen::Vector2f expected(static_cast<float>(rot.at<double>(0, 0) * p.x() + rot.at<double>(0, 1) * p.y() + rot.at<double>(0, 2)),
                                   static_cast<float>(rot.at<double>(1, 0) * p.x() + rot.at<double>(1, 1) * p.y() + rot.at<double>(1, 2)));
    good += (t.uv - expected).norm() <= max_err_px;
  }
  return good;
}

TEST(FeatureTracker, DescriptorFallbackRefindsTracksAcrossATurn) {
  int matched_plain = 0, matched_oriented = 0;
  const int good_plain = RefoundWithinPx(false, 2.0, &matched_plain);
  const int good_oriented = RefoundWithinPx(true, 2.0, &matched_oriented);
  std::cout << "descriptor fallback under a 25 deg turn: unoriented " << matched_plain << " matched, oriented "
            << matched_oriented << "; tracks within 2 px " << good_plain << " / " << good_oriented << "\n";
  EXPECT_GT(matched_oriented, 5 * std::max(matched_plain, 10));
  EXPECT_GT(good_oriented, good_plain + 50);
}

}  // namespace
}  // namespace mbslam

namespace mbslam {
namespace {

// A view tracked over four images (2 px apart), then one 120 px away (a low frame rate):
// KLT loses the tracks. Taken 33 ms after the last, the image is rejected as a glitch
// (nearly every established track lost at once); taken 500 ms after it, it is a wide
// baseline (tracking.wide_baseline_min_interval_us): not a glitch, and the fallback
// describes both sides alike and re-finds the tracks.
struct WideRun {
  bool rejected = false;
  int matched = 0;  // re-found by descriptors
  int good = 0;     // tracks seen in the last image within 2 px of the truth
};
WideRun RunShifted(int64_t interval_us, bool fallback = true) {
  TrackerOptions o;
  o.descriptor_fallback = fallback;
  FeatureTracker tracker(o);
  const cv::Mat base = testing_images::Texture(640, 480, 4);
  for (int f = 0; f < 4; ++f) {
    TrackingHints hints;
    hints.interval_us = 33333;
    tracker.TrackFrame(Pyramid(Shift(base, 2.0f * f, 0.0f)), f, hints);
  }
  std::map<int64_t, Eigen::Vector2f> start;
  for (const Track& t : tracker.tracks()) start[t.id] = t.uv;
  TrackingHints hints;
  hints.interval_us = interval_us;
  tracker.TrackFrame(Pyramid(Shift(base, 6.0f + 120.0f, 40.0f)), 4, hints);
  WideRun run;
  run.rejected = tracker.stats().rejected;
  run.matched = tracker.stats().descriptor_matched;
  for (const Track& t : tracker.tracks()) {
    auto it = start.find(t.id);
    if (it == start.end() || t.last_seen_frame != 4) continue;
    run.good += (t.uv - it->second - Eigen::Vector2f(120.0f, 40.0f)).norm() <= 2.0f;
  }
  return run;
}

TEST(FeatureTracker, WideBaselineFallbackDescribesBothSidesAlike) {
  const WideRun video = RunShifted(33333);
  const WideRun wide = RunShifted(500000);
  const WideRun klt_only = RunShifted(500000, /*fallback=*/false);
  std::cout << "120 px apart: 33 ms " << (video.rejected ? "rejected" : "taken") << ", " << video.matched
            << " re-found; 500 ms " << (wide.rejected ? "rejected" : "taken") << ", " << wide.matched << " re-found, "
            << wide.good << " tracks within 2 px (" << klt_only.good << " without the fallback)\n";
  EXPECT_TRUE(video.rejected);
  EXPECT_FALSE(wide.rejected);
  EXPECT_LT(klt_only.good, 20);
  // The tracks within 2 px are the fallback's (KLT keeps few), and nearly all it re-found.
  EXPECT_GT(wide.good - klt_only.good, 200);
  EXPECT_GT(wide.good - klt_only.good, 0.8 * wide.matched);
}

// The same jump with a glitch test off: at video rate the usual fallback re-finds few.
TEST(FeatureTracker, AtVideoRateTheUsualFallbackRefindsFew) {
  TrackerOptions o;
  o.glitch_max_survival = 0.0;
  FeatureTracker tracker(o);
  const cv::Mat base = testing_images::Texture(640, 480, 4);
  TrackingHints hints;
  hints.interval_us = 33333;
  tracker.TrackFrame(Pyramid(base), 0, hints);
  tracker.TrackFrame(Pyramid(Shift(base, 120.0f, 40.0f)), 1, hints);
  EXPECT_LT(tracker.stats().descriptor_matched, 50);
}

}  // namespace
}  // namespace mbslam
