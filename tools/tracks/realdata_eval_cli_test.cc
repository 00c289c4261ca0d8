// mbslam-eval-realdata end to end on synthetic DAVIS / CamVid folders and run logs (known
// answers), and oracle runs built from the shared data's own ground truth (skipped when
// ../shared/data is absent).

#include <gtest/gtest.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <map>
#include <string>
#include <vector>

#include "common/lcm/lcm_log.h"
#include "mbslam/objects_t.hpp"
#include "mbslam/tracks_t.hpp"
#include "tools/eval/datasets.h"
#include "tools/eval/json.h"
#include "tools/tracks/realdata_scoring.h"
#include "test/tools/feature_tracks.h"
#include "test/tools/run_command.h"

namespace mbslam {
namespace eval {
namespace {

namespace fs = std::filesystem;

std::string Bin() { return testing_util::ToolPath("mbslam-eval-realdata"); }

int RunCli(const std::string& args, Json* json) {
  std::string out;
  const int status = testing_util::RunCommand(Bin() + " " + args + " 2>/dev/null", &out);
  if (!Json::Parse(testing_util::LastLine(out), json)) *json = Json();
  return status;
}

double Get(const Json& j, const std::string& key) {
  const Json* v = j.Find(key);
  return v ? v->AsDouble() : NAN;
}

class RealDataCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(Bin())) GTEST_SKIP() << Bin() << " not built";
    dir_ = fs::temp_directory_path() / ("realdata_cli_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  fs::path dir_;
};

using testing_util::FeatureTrack;

void WriteTracks(LcmLogWriter* w, int64_t seq, int width, int height,
                 const std::vector<mbslam::feature_track_t>& tracks,
                 const std::vector<std::vector<cv::Point2f>>& hulls) {
  const ChannelOptions ch;
  mbslam::tracks_t t{};
  t.utime = 1000 + seq * 41667;
  t.frame_seq = seq;
  t.width = width;
  t.height = height;
  t.tracks = tracks;
  t.num_tracks = static_cast<int32_t>(tracks.size());
  mbslam::objects_t o{};
  o.utime = t.utime;
  o.frame_seq = seq;
  int id = 1;
  for (const auto& h : hulls) {
    mbslam::object_t obj{};
    obj.id = id++;
    obj.orientation[0] = 1.0;
    obj.hull.body_id = obj.id;
    for (const auto& p : h) {
      obj.hull.u.push_back(p.x);
      obj.hull.v.push_back(p.y);
    }
    obj.hull.num_points = static_cast<int32_t>(h.size());
    t.hulls.push_back(obj.hull);
    o.objects.push_back(obj);
  }
  t.num_hulls = static_cast<int32_t>(t.hulls.size());
  o.num_objects = static_cast<int32_t>(o.objects.size());
  ASSERT_TRUE(w->Write(ch.perception_tracks, t.utime, t).ok());
  ASSERT_TRUE(w->Write(ch.perception_objects, t.utime, o).ok());
}

TEST_F(RealDataCli, DavisKnownAnswers) {
  // Two sequences of two 100x100 frames, mask = square [20, 60)^2.
  cv::Mat mask(100, 100, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(20, 20, 40, 40)).setTo(255);
  const cv::Mat image(100, 100, CV_8UC3, cv::Scalar(80, 80, 80));
  for (const std::string seq : {"aa", "bb"}) {
    fs::create_directories(dir_ / "davis/Annotations" / seq);
    fs::create_directories(dir_ / "davis/JPEGImages" / seq);
    fs::create_directories(dir_ / "runs" / seq);
    for (int i = 0; i < 2; ++i) {
      const std::string stem = "0000" + std::to_string(i);
      ASSERT_TRUE(cv::imwrite((dir_ / "davis/Annotations" / seq / (stem + ".png")).string(), mask));
      ASSERT_TRUE(cv::imwrite((dir_ / "davis/JPEGImages" / seq / (stem + ".jpg")).string(), image));
    }
  }
  Status st;
  {
    // aa: frame 0 P 1 R 1/2 J 1 (hull = mask); frame 1 P 1/2, R 1, J 0.25 (quarter hull).
    auto w = LcmLogWriter::Open((dir_ / "runs/aa/out.lcmlog").string(), &st);
    ASSERT_TRUE(w);
    WriteTracks(w.get(), 0, 100, 100, {FeatureTrack(1, 30, 30, 1), FeatureTrack(2, 40, 40, 0), FeatureTrack(3, 5, 5, 0)},
                {{{20, 20}, {59, 20}, {59, 59}, {20, 59}}});
    WriteTracks(w.get(), 1, 100, 100, {FeatureTrack(1, 30, 30, 1), FeatureTrack(4, 80, 80, 1)},
                {{{20, 20}, {39, 20}, {39, 39}, {20, 39}}});
    w->Flush();
  }
  {
    // bb: frame 0 nothing moving (P undefined, R 0, J 0); frame 1 no output at all.
    auto w = LcmLogWriter::Open((dir_ / "runs/bb/out.lcmlog").string(), &st);
    ASSERT_TRUE(w);
    WriteTracks(w.get(), 0, 100, 100, {FeatureTrack(1, 30, 30, 0), FeatureTrack(2, 90, 90, 0)}, {});
    w->Flush();
  }
  Json j;
  ASSERT_EQ(RunCli("davis --root " + (dir_ / "davis").string() + " --runs " + (dir_ / "runs").string() +
                       " --per-frame-dir " + (dir_ / "per_frame").string(),
                   &j),
            0);
  const Json* per = j.Find("per_sequence");
  ASSERT_NE(per, nullptr);
  const Json* aa = per->Find("aa");
  const Json* bb = per->Find("bb");
  ASSERT_TRUE(aa && bb);
  EXPECT_DOUBLE_EQ(Get(*aa, "precision"), 0.75);
  EXPECT_DOUBLE_EQ(Get(*aa, "recall"), 0.75);
  EXPECT_DOUBLE_EQ(Get(*aa, "iou"), 0.625);
  EXPECT_TRUE(std::isnan(Get(*bb, "precision")));  // null: no image had a moving feature
  EXPECT_DOUBLE_EQ(Get(*bb, "recall"), 0.0);
  EXPECT_DOUBLE_EQ(Get(*bb, "iou"), 0.0);
  EXPECT_DOUBLE_EQ(Get(*bb, "frames_without_output"), 1);
  EXPECT_DOUBLE_EQ(Get(j, "mean_precision"), 0.75);  // bb has none: skipped
  EXPECT_DOUBLE_EQ(Get(j, "mean_recall"), 0.375);
  EXPECT_DOUBLE_EQ(Get(j, "mean_iou"), 0.3125);
  EXPECT_DOUBLE_EQ(Get(j, "frames"), 4);
  EXPECT_DOUBLE_EQ(Get(j, "frames_precision_undefined"), 2);
  EXPECT_DOUBLE_EQ(Get(j, "frames_recall_undefined"), 1);
  EXPECT_TRUE(fs::exists(dir_ / "per_frame/aa.csv"));
}

// A static scene: every moving label is false, every object a phantom.
TEST_F(RealDataCli, StaticSceneKnownAnswers) {
  Status st;
  auto w = LcmLogWriter::Open((dir_ / "out.lcmlog").string(), &st);
  ASSERT_TRUE(w);
  // Image 0: 1 of 4 moving (object 1), one unassigned; image 1: none; image 2: 2 of 4
  // (objects 1 and 3), one new (not scored).
  WriteTracks(w.get(), 0, 80, 60,
              {FeatureTrack(1, 10, 10, 1), FeatureTrack(2, 50, 10, 0), FeatureTrack(3, 50, 20, 0),
               FeatureTrack(4, 50, 30, -1)},
              {});
  WriteTracks(w.get(), 1, 80, 60, {FeatureTrack(1, 10, 10, 0), FeatureTrack(2, 50, 10, 0)}, {});
  WriteTracks(w.get(), 2, 80, 60,
              {FeatureTrack(1, 10, 10, 1), FeatureTrack(2, 50, 10, 3), FeatureTrack(3, 50, 20, 0),
               FeatureTrack(5, 20, 20, 0), FeatureTrack(6, 30, 30, 2, 1, mbslam::feature_track_t::FLAG_NEW)},
              {});
  w->Flush();
  Json j;
  ASSERT_EQ(RunCli("static --run " + (dir_ / "out.lcmlog").string() + " --name test", &j), 0);
  EXPECT_DOUBLE_EQ(Get(j, "static_false_moving_fraction"), 3.0 / 10.0);
  EXPECT_DOUBLE_EQ(Get(j, "static_frames_with_moving_share"), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(Get(j, "static_phantom_objects"), 2);
  EXPECT_DOUBLE_EQ(Get(j, "moving_features"), 3);
  EXPECT_DOUBLE_EQ(Get(j, "features"), 10);
  EXPECT_DOUBLE_EQ(Get(j, "unassigned_features"), 1);
  EXPECT_DOUBLE_EQ(Get(j, "frames"), 3);
  // Bad options and a log without tracks: errors, not figures.
  EXPECT_EQ(RunCli("static --run " + (dir_ / "out.lcmlog").string() + " --bogus 1", &j), 2);
  EXPECT_EQ(RunCli("static", &j), 2);
  EXPECT_EQ(RunCli("static --run " + (dir_ / "missing.lcmlog").string(), &j), 1);
}

TEST_F(RealDataCli, CamVidKnownAnswers) {
  cv::Mat labels(60, 80, CV_8UC1, cv::Scalar(kCamVidBuilding));
  labels(cv::Rect(40, 0, 40, 60)).setTo(kCamVidCar);
  fs::create_directories(dir_ / "camvid/images");
  fs::create_directories(dir_ / "camvid/labels");
  for (const std::string stem : {"f_001", "f_002"}) {
    ASSERT_TRUE(cv::imwrite((dir_ / "camvid/labels" / (stem + ".png")).string(), labels));
    ASSERT_TRUE(cv::imwrite((dir_ / "camvid/images" / (stem + ".png")).string(), labels));
  }
  Status st;
  auto w = LcmLogWriter::Open((dir_ / "out.lcmlog").string(), &st);
  ASSERT_TRUE(w);
  // Moving: 1 on building, 3 on car; static: 1 on car, 5 on building.
  WriteTracks(w.get(), 0, 80, 60,
              {FeatureTrack(1, 10, 10, 1), FeatureTrack(2, 50, 10, 1), FeatureTrack(3, 50, 20, 1), FeatureTrack(4, 50, 30, 0),
               FeatureTrack(5, 10, 20, 0), FeatureTrack(6, 10, 30, 0)},
              {});
  WriteTracks(w.get(), 1, 80, 60, {FeatureTrack(2, 60, 10, 2), FeatureTrack(5, 10, 20, 0), FeatureTrack(6, 10, 30, 0), FeatureTrack(7, 10, 40, 0)}, {});
  w->Flush();
  Json j;
  ASSERT_EQ(RunCli("camvid --root " + (dir_ / "camvid").string() + " --run " + (dir_ / "out.lcmlog").string(), &j), 0);
  EXPECT_DOUBLE_EQ(Get(j, "moving_on_static_classes"), 0.25);
  EXPECT_DOUBLE_EQ(Get(j, "moving_on_movable_classes"), 0.75);
  EXPECT_DOUBLE_EQ(Get(j, "movable_features_labelled_moving"), 0.75);
  EXPECT_DOUBLE_EQ(Get(j, "moving_features"), 4);
  EXPECT_DOUBLE_EQ(Get(j, "frames"), 2);
  // Bad options: the usage's exit status, not a crash or a silent default.
  const std::string camvid = "camvid --root " + (dir_ / "camvid").string() + " --run " + (dir_ / "out.lcmlog").string();
  EXPECT_EQ(RunCli(camvid + " --bogus 1", &j), 2);
  EXPECT_EQ(RunCli(camvid + " --overlay-dir " + (dir_ / "ov").string() + " --overlay-every 2x", &j), 2);
  EXPECT_FALSE(fs::exists(dir_ / "ov"));

  // The diagnostic dump: one line per scored feature with its truth class and its
  // distance to the nearest car / pedestrian / cyclist pixel (exact Euclidean, px).
  ASSERT_EQ(RunCli("camvid --root " + (dir_ / "camvid").string() + " --run " + (dir_ / "out.lcmlog").string() +
                       " --dump " + (dir_ / "features.csv").string(),
                   &j),
            0);
  std::ifstream dump(dir_ / "features.csv");
  std::string header, line;
  ASSERT_TRUE(std::getline(dump, header));
  EXPECT_EQ(header.substr(header.rfind(',') + 1), "truth_dist_px");
  std::map<std::string, std::string> dist_of;  // "frame,id" -> truth_dist_px
  int lines = 0;
  while (std::getline(dump, line)) {
    ++lines;
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    ASSERT_EQ(cells.size(), 15u) << line;
    dist_of[cells[1] + "," + cells[2]] = cells.back();
  }
  EXPECT_EQ(lines, 10);
  EXPECT_NEAR(std::stod(dist_of["0,1"]), 30.0, 1e-3);  // (10, 10): the car starts at x = 40
  EXPECT_NEAR(std::stod(dist_of["0,2"]), 0.0, 1e-9);   // on the car
  EXPECT_NEAR(std::stod(dist_of["1,7"]), 30.0, 1e-3);
}

// ---------------------------------------------------------------- shared data (oracles)

#define REQUIRE_DATA(name, var)                                                                 \
  const std::string var = DataSetPath(name);                                                    \
  if (var.empty()) {                                                                            \
    GTEST_SKIP() << "data set '" << name << "' not found under " << DataRoot()                  \
                 << " (set MBSLAM_DATA or put ../shared/data next to the repository); skipped"; \
  }

// A run that labels a grid of features moving exactly where the ground truth says so, with
// the convex hull of the mask as the object hull: precision = recall = 1, J = mask / hull.
TEST(RealDataSharedData, DavisOracleRun) {
  REQUIRE_DATA("davis2016", root);
  std::vector<DavisSequence> seqs;
  ASSERT_TRUE(ReadDavis(root, &seqs).ok());
  const DavisSequence& seq = seqs.front();
  std::map<int64_t, PerceptionFrame> run;
  for (size_t i = 0; i < seq.masks.size(); ++i) {
    cv::Mat mask;
    ASSERT_TRUE(LoadBinaryMask(seq.masks[i], &mask).ok());
    PerceptionFrame& f = run[static_cast<int64_t>(i)];
    f.frame_seq = static_cast<int64_t>(i);
    f.width = mask.cols;
    f.height = mask.rows;
    f.has_tracks = f.has_objects = true;
    for (int y = 5; y < mask.rows; y += 10) {
      for (int x = 5; x < mask.cols; x += 10) {
        LabelledFeature lf;
        lf.u = x;
        lf.v = y;
        lf.moving = mask.at<uint8_t>(y, x) != 0;
        f.features.push_back(lf);
        f.body_ids.push_back(lf.moving ? 1 : 0);
      }
    }
    std::vector<cv::Point> nz, hull;
    cv::findNonZero(mask, nz);
    if (nz.size() >= 3) {
      cv::convexHull(nz, hull);
      ImagePolygon p;
      p.body_id = 1;
      for (const auto& q : hull) p.points.emplace_back(static_cast<float>(q.x), static_cast<float>(q.y));
      f.object_hulls.push_back(p);
    }
  }
  MaskSequenceScore s;
  ASSERT_TRUE(ScoreDavisSequence(seq, run, &s).ok());
  EXPECT_EQ(s.frames, static_cast<int>(seq.masks.size()));
  EXPECT_EQ(s.frames_without_output, 0);
  EXPECT_DOUBLE_EQ(s.mean_precision, 1.0);
  EXPECT_DOUBLE_EQ(s.mean_recall, 1.0);
  EXPECT_GT(s.mean_iou, 0.5) << seq.name;  // a convex hull over-covers a non-convex mask
  EXPECT_LE(s.mean_iou, 1.0);
}

TEST(RealDataSharedData, CamVidOracleRun) {
  REQUIRE_DATA("camvid_0016E5_15hz", root);
  std::vector<CamVidFrame> frames;
  ASSERT_TRUE(ReadCamVid(root, &frames).ok());
  std::map<int64_t, PerceptionFrame> run;
  for (size_t i = 0; i < frames.size(); i += 10) {
    const cv::Mat labels = cv::imread(frames[i].label, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(labels.empty());
    PerceptionFrame& f = run[static_cast<int64_t>(i)];
    f.frame_seq = static_cast<int64_t>(i);
    f.width = labels.cols;
    f.height = labels.rows;
    f.has_tracks = true;
    for (int y = 3; y < labels.rows; y += 6) {
      for (int x = 3; x < labels.cols; x += 6) {
        LabelledFeature lf;
        lf.u = x;
        lf.v = y;
        lf.moving = IsCamVidMovableClass(labels.at<uint8_t>(y, x));
        f.features.push_back(lf);
        f.body_ids.push_back(lf.moving ? 1 : 0);
      }
    }
  }
  CamVidRunScore s;
  ASSERT_TRUE(ScoreCamVid(frames, run, &s).ok());
  EXPECT_GT(s.moving.moving, 0);
  EXPECT_DOUBLE_EQ(s.moving_on_static, 0.0);
  EXPECT_DOUBLE_EQ(s.moving_on_movable, 1.0);
  EXPECT_DOUBLE_EQ(s.movable_labelled_moving, 1.0);
  EXPECT_EQ(s.frames_without_output, static_cast<int>(frames.size()) - s.frames);
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
