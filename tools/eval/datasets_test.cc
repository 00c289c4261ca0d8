// Readers for every set in ../shared/data (skipped with a message when the data is not
// there) and for folders of *.tracks.txt.

#include "tools/eval/datasets.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <set>

namespace mbslam {
namespace eval {
namespace {

namespace fs = std::filesystem;

#define REQUIRE_DATA(name, var)                                                        \
  const std::string var = DataSetPath(name);                                           \
  if (var.empty()) {                                                                   \
    GTEST_SKIP() << "data set '" << name << "' not found under " << DataRoot()         \
                 << " (set MBSLAM_DATA or put ../shared/data next to the repository)"; \
  }

TEST(Tracks, ParseWriteAndFolder) {
  const std::string text =
      "3 2 640 480\n"
      "1 2 1\n"
      "10.5 20 11 21\n"
      "100 200 nan nan\n"
      "5 6 7 8\n";
  TrackSet set;
  ASSERT_TRUE(ParseTracks(text, &set).ok());
  EXPECT_EQ(set.num_points(), 3);
  EXPECT_EQ(set.num_frames(), 2);
  EXPECT_EQ(set.width, 640);
  EXPECT_EQ(set.NumGroups(), 2);
  EXPECT_DOUBLE_EQ(set.tracks[0][1].y(), 21.0);
  EXPECT_TRUE(std::isnan(set.tracks[1][1].x()));
  const fs::path dir = fs::temp_directory_path() / ("mbslam_tracks_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  set.name = "b";
  ASSERT_TRUE(WriteTracksFile((dir / "b.tracks.txt").string(), set).ok());
  set.labels = {3, 3, 3};
  ASSERT_TRUE(WriteTracksFile((dir / "a.tracks.txt").string(), set).ok());
  std::vector<TrackSet> sets;
  ASSERT_TRUE(ReadTracksFolder(dir.string(), &sets).ok());
  ASSERT_EQ(sets.size(), 2u);
  EXPECT_EQ(sets[0].name, "a");
  EXPECT_EQ(sets[0].NumGroups(), 1);
  EXPECT_EQ(sets[1].name, "b");
  EXPECT_TRUE(std::isnan(sets[1].tracks[1][1].y()));
  EXPECT_DOUBLE_EQ(sets[1].tracks[0][0].x(), 10.5);
  ASSERT_TRUE(WriteLabelFile((dir / "p.txt").string(), {4, -1, 2}).ok());
  std::vector<int> labels;
  ASSERT_TRUE(ReadLabelFile((dir / "p.txt").string(), &labels).ok());
  EXPECT_EQ(labels, std::vector<int>({4, -1, 2}));
  fs::remove_all(dir);
  EXPECT_FALSE(ParseTracks("2 2 640 480\n1 1\n1 2 3 4\n", &set).ok());  // a track missing
  EXPECT_FALSE(ParseTracks("2 2 640 480\n1\n", &set).ok());             // a label missing
}

TEST(CamVid, MovingFeatureStats) {
  cv::Mat labels(10, 10, CV_8UC1, cv::Scalar(kCamVidRoad));
  labels(cv::Rect(5, 0, 5, 5)).setTo(kCamVidCar);
  labels.at<uint8_t>(9, 9) = kCamVidVoid;
  const std::vector<LabelledFeature> features = {
      {1, 1, true}, {7, 2, true}, {9, 9, true}, {2, 2, false}, {20, 20, true}};
  const CamVidFeatureStats s = CamVidMovingFeatureStats(features, labels);
  EXPECT_EQ(s.moving, 3);
  EXPECT_EQ(s.on_static, 1);
  EXPECT_EQ(s.on_movable, 1);
  EXPECT_EQ(s.on_void, 1);
  EXPECT_DOUBLE_EQ(s.static_fraction, 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.movable_fraction, 1.0 / 3.0);
}

TEST(SharedData, Hopkins155) {
  REQUIRE_DATA("hopkins155", root);
  std::vector<TrackSet> sets;
  ASSERT_TRUE(ReadTracksFolder(root, &sets).ok());
  EXPECT_GE(sets.size(), 155u);
  int two = 0, three = 0;
  for (const auto& s : sets) {
    EXPECT_EQ(static_cast<int>(s.labels.size()), s.num_points()) << s.name;
    EXPECT_GE(s.num_frames(), 2) << s.name;
    EXPECT_GT(s.width, 0);
    if (s.name == "dancing") {
      continue;
    }
    two += s.NumGroups() == 2;
    three += s.NumGroups() == 3;
  }
  EXPECT_EQ(two, 120);
  EXPECT_EQ(three, 35);
}

TEST(SharedData, Davis2016) {
  REQUIRE_DATA("davis2016", root);
  std::vector<DavisSequence> seqs;
  ASSERT_TRUE(ReadDavis(root, &seqs).ok());
  EXPECT_EQ(seqs.size(), 10u);
  for (const auto& s : seqs) {
    ASSERT_FALSE(s.masks.empty()) << s.name;
    EXPECT_EQ(s.masks.size(), s.images.size());
  }
  cv::Mat mask;
  ASSERT_TRUE(LoadBinaryMask(seqs[0].masks[0], &mask).ok());
  EXPECT_EQ(mask.type(), CV_8UC1);
  EXPECT_EQ(mask.size(), cv::Size(854, 480));
  const int inside = cv::countNonZero(mask);
  EXPECT_GT(inside, 0);
  EXPECT_LT(inside, static_cast<int>(mask.total()));
}

TEST(SharedData, CamVid) {
  REQUIRE_DATA("camvid_0016E5_15hz", root);
  std::vector<CamVidFrame> frames;
  ASSERT_TRUE(ReadCamVid(root, &frames).ok());
  EXPECT_EQ(frames.size(), 101u);
  EXPECT_TRUE(IsCamVidStaticClass(kCamVidRoad));
  EXPECT_TRUE(IsCamVidMovableClass(kCamVidPedestrian));
  EXPECT_FALSE(IsCamVidStaticClass(kCamVidVoid));
  EXPECT_FALSE(IsCamVidMovableClass(kCamVidVoid));
  const cv::Mat labels = cv::imread(frames[0].label, cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(labels.empty());
  EXPECT_EQ(labels.size(), cv::Size(480, 360));
  double max_label;
  cv::minMaxLoc(labels, nullptr, &max_label);
  EXPECT_LE(max_label, kCamVidVoid);
  EXPECT_GT(cv::countNonZero(labels == kCamVidRoad), 1000);  // a street scene
}

TEST(SharedData, TumSubset) {
  REQUIRE_DATA("tum_fr3_cabinet_subset", root);
  TumSubset tum;
  ASSERT_TRUE(ReadTumSubset(root, &tum).ok());
  EXPECT_EQ(tum.truth.size(), 58u);
  EXPECT_EQ(tum.images.size(), 58u);
  EXPECT_EQ(tum.truth.front().utime, 1341841278842700);
  EXPECT_DOUBLE_EQ(tum.intrinsics.fx, 535.4);
}

TEST(SharedData, TartanAirSubset) {
  REQUIRE_DATA("tartanair_indoor_subset", root);
  TartanAirSubset ta;
  ASSERT_TRUE(ReadTartanAirSubset(root, 100000, &ta).ok());
  EXPECT_EQ(ta.truth.size(), 189u);
  EXPECT_EQ(ta.truth[5].utime, 500000);
  double length = 0.0;
  for (size_t i = 1; i < ta.truth.size(); ++i) {
    length += (ta.truth[i].pose.translation - ta.truth[i - 1].pose.translation).norm();
  }
  EXPECT_NEAR(length, 14.6, 1.5);  // "~14.6 m path" (README)
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
