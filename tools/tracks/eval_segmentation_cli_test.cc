// mbslam-eval-segmentation end to end on a one-image synthetic sequence (known answers):
// moving-feature recall and precision, and the same away from the mover's silhouette.

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "common/lcm/channels.h"
#include "common/lcm/lcm_log.h"
#include "common/testing/temp_dir.h"
#include "mbslam/ground_truth_t.hpp"
#include "mbslam/tracks_t.hpp"
#include "tools/eval/json.h"
#include "test/tools/feature_tracks.h"
#include "test/tools/run_command.h"

namespace mbslam {
namespace eval {
namespace {

namespace fs = std::filesystem;

std::string Bin() { return testing_util::ToolPath("mbslam-eval-segmentation"); }

double Get(const Json& j, const std::string& key) {
  const Json* v = j.Find(key);
  return v ? v->AsDouble() : NAN;
}

using testing_util::FeatureTrack;

// A 64x48 image whose body 1, the square [20, 40) x [10, 30), moves.
void WriteSequence(const fs::path& dir) {
  fs::create_directories(dir / "masks");
  cv::Mat mask(48, 64, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(20, 10, 20, 20)).setTo(1);
  ASSERT_TRUE(cv::imwrite((dir / "masks/000000.png").string(), mask));
  mbslam::ground_truth_t gt{};
  gt.utime = 1000;
  gt.frame_seq = 0;
  gt.source = "test";
  mbslam::body_state_t b{};
  b.id = 1;
  b.name = "box";
  b.orientation[0] = 1.0;
  b.linear_velocity[0] = 1.0;
  b.visible = 1;
  gt.bodies.push_back(b);
  gt.num_bodies = 1;
  Status st;
  auto w = LcmLogWriter::Open((dir / "sequence.lcmlog").string(), &st);
  ASSERT_TRUE(w) << st.message();
  ASSERT_TRUE(w->Write(ChannelOptions().ground_truth, gt.utime, gt).ok());
}

void WriteRun(const fs::path& path, const std::vector<mbslam::feature_track_t>& features) {
  mbslam::tracks_t t{};
  t.utime = 1000;
  t.frame_seq = 0;
  t.width = 64;
  t.height = 48;
  t.tracks = features;
  t.num_tracks = static_cast<int32_t>(features.size());
  Status st;
  auto w = LcmLogWriter::Open(path.string(), &st);
  ASSERT_TRUE(w) << st.message();
  ASSERT_TRUE(w->Write(ChannelOptions().perception_tracks, t.utime, t).ok());
}

TEST(EvalSegmentationCli, RecallAndPrecisionWithAndWithoutTheSilhouette) {
  if (!fs::exists(Bin())) GTEST_SKIP() << Bin() << " not built";
  const fs::path dir = testing_util::MakeTestTempDir("eval_segmentation_cli");
  ASSERT_NO_FATAL_FAILURE(WriteSequence(dir / "seq"));
  // On the mover: deep inside and labelled moving (TP), on its edge pixel and labelled
  // moving (TP), inside and labelled static (FN). Off it: 2 px left of its edge labelled
  // moving (FP), 3 px left of it labelled moving (FP), far and static (TN).
  ASSERT_NO_FATAL_FAILURE(WriteRun(dir / "run.lcmlog", {FeatureTrack(1, 30, 20, 1), FeatureTrack(2, 20, 20, 1),
                                                         FeatureTrack(3, 35, 25, 0), FeatureTrack(4, 18, 20, 1),
                                                         FeatureTrack(5, 17, 15, 1), FeatureTrack(6, 55, 40, 0)}));
  std::string out;
  const std::string args = " --run " + (dir / "run.lcmlog").string() + " --sequence " + (dir / "seq").string() +
                           " --settle 0";
  ASSERT_EQ(testing_util::RunCommand(Bin() + args + " 2>/dev/null", &out), 0) << out;
  Json j;
  ASSERT_TRUE(Json::Parse(testing_util::LastLine(out), &j)) << out;
  EXPECT_NEAR(Get(j, "moving_recall"), 2.0 / 3.0, 1e-3);
  EXPECT_NEAR(Get(j, "moving_precision"), 0.5, 1e-3);
  // 3 px or more from the silhouette: features 1, 3 (5 px in) and 5 (3 px out) are scored.
  EXPECT_NEAR(Get(j, "silhouette_px"), 3.0, 1e-9);
  EXPECT_NEAR(Get(j, "moving_recall_off_silhouette"), 0.5, 1e-3);
  EXPECT_NEAR(Get(j, "moving_precision_off_silhouette"), 0.5, 1e-3);
  // A band of 0 scores them all.
  ASSERT_EQ(testing_util::RunCommand(Bin() + args + " --silhouette-px 0 2>/dev/null", &out), 0) << out;
  ASSERT_TRUE(Json::Parse(testing_util::LastLine(out), &j)) << out;
  EXPECT_NEAR(Get(j, "moving_recall_off_silhouette"), 2.0 / 3.0, 1e-3);
  EXPECT_NEAR(Get(j, "moving_precision_off_silhouette"), 0.5, 1e-3);
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
