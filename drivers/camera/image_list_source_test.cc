#include "drivers/camera/image_list_source.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "drivers/camera/camera_test_util.h"
#include "mbslam/image_t.hpp"

namespace mbslam {
namespace {

namespace fs = std::filesystem;
using testing_util::MakeTempDir;
using testing_util::MakeTestImage;
using testing_util::WriteTextFile;

bool Identical(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

// Reads every frame; returns the frames and counts bad ones.
std::vector<Frame> ReadAll(FrameSource* source, int* bad = nullptr) {
  std::vector<Frame> frames;
  Frame frame;
  SourceStatus status;
  while (true) {
    const FrameSource::ReadResult r = source->Next(&frame, &status);
    if (r == FrameSource::ReadResult::kEnd || r == FrameSource::ReadResult::kError) break;
    if (r == FrameSource::ReadResult::kBadFrame) {
      if (bad) ++*bad;
      continue;
    }
    frames.push_back(frame);
  }
  return frames;
}

TEST(NaturalLess, OrdersEmbeddedNumbersByValue) {
  std::vector<std::string> names = {"img10.png", "img2.png", "img1.png", "a.png", "img02.png"};
  std::sort(names.begin(), names.end(), NaturalLess);
  EXPECT_EQ(names, (std::vector<std::string>{"a.png", "img1.png", "img02.png", "img2.png",
                                             "img10.png"}));
  EXPECT_TRUE(NaturalLess("000009.png", "000010.png"));
  EXPECT_FALSE(NaturalLess("x", "x"));
}

TEST(ImageFolder, SortedFramesTimedByRate) {
  const std::string dir = MakeTempDir("folder");
  std::vector<cv::Mat> images;
  for (int i : {0, 1, 2, 10}) {
    images.push_back(MakeTestImage(20, 10, 3, i));
    cv::imwrite(dir + "/frame" + std::to_string(i) + ".png", images.back());
  }
  WriteTextFile(dir + "/notes.txt", "not an image");
  FolderOptions options;
  options.rate_hz = 30.0;
  options.time_origin_s = 2.0;
  ImageListSource source("folder", dir, options, GroundTruthOptions());
  ASSERT_TRUE(source.Open().ok());
  EXPECT_EQ(source.num_frames(), 4);
  const std::vector<Frame> frames = ReadAll(&source);
  ASSERT_EQ(frames.size(), 4u);
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_TRUE(Identical(frames[i].image, images[i])) << i;
    EXPECT_EQ(frames[i].utime, 2000000 + std::llround(static_cast<double>(i) * 1e6 / 30.0));
    EXPECT_EQ(frames[i].file_encoding, mbslam::image_t::ENCODING_PNG);
    EXPECT_FALSE(frames[i].has_truth_source);
  }
  EXPECT_EQ(frames[3].utime, 2100000);
  ASSERT_TRUE(source.Rewind().ok());
  EXPECT_EQ(ReadAll(&source).size(), 4u);
  ASSERT_TRUE(source.SeekToIndex(3));
  const std::vector<Frame> rest = ReadAll(&source);
  ASSERT_EQ(rest.size(), 1u);
  EXPECT_EQ(rest[0].index, 3);
}

TEST(ImageFolder, TimestampsFileInThreeForms) {
  const std::string dir = MakeTempDir("stamps");
  for (int i = 0; i < 3; ++i) cv::imwrite(dir + "/" + std::to_string(i) + ".png", MakeTestImage(8, 8, 1, i));
  FolderOptions options;
  options.timestamps_file = dir + "/plain.txt";
  WriteTextFile(options.timestamps_file, "# t\n10.5\n10.6\n10.75\n");
  ImageListSource a("folder", dir, options, GroundTruthOptions());
  ASSERT_TRUE(a.Open().ok());
  std::vector<Frame> frames = ReadAll(&a);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[2].utime, 10750000);

  options.timestamps_file = dir + "/by_name.txt";
  options.timestamps_unit = "ns";
  WriteTextFile(options.timestamps_file, "2.png 3000000000\n0.png 1000000000\n1.png 2000000500\n");
  ImageListSource b("folder", dir, options, GroundTruthOptions());
  ASSERT_TRUE(b.Open().ok());
  frames = ReadAll(&b);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0].utime, 1000000);
  EXPECT_EQ(frames[1].utime, 2000001);

  options.timestamps_file = dir + "/by_index.txt";
  options.timestamps_unit = "us";
  WriteTextFile(options.timestamps_file, "0 100\n1 200\n2 300\n");
  ImageListSource c("folder", dir, options, GroundTruthOptions());
  ASSERT_TRUE(c.Open().ok());
  EXPECT_EQ(ReadAll(&c)[2].utime, 300);

  for (const std::string& bad : {std::string("1\n2\n"), std::string("1\n2\n3\n4\n"),
                                 std::string("3\n2\n1\n"), std::string("nope.png 1\n"),
                                 std::string("0 1 2\n")}) {
    options.timestamps_file = dir + "/bad.txt";
    WriteTextFile(options.timestamps_file, bad);
    ImageListSource d("folder", dir, options, GroundTruthOptions());
    const SourceStatus st = d.Open();
    EXPECT_FALSE(st.ok()) << bad;
    EXPECT_EQ(st.kind(), SourceError::kConfig) << bad;
  }
}

TEST(ImageFolder, CorruptAndMissingImagesAreBadFramesNotCrashes) {
  const std::string dir = MakeTempDir("corrupt");
  cv::imwrite(dir + "/000.png", MakeTestImage(8, 8, 1, 0));
  WriteTextFile(dir + "/001.png", "garbage, not a png");
  WriteTextFile(dir + "/002.jpg", "");
  cv::imwrite(dir + "/003.png", MakeTestImage(8, 8, 1, 3));
  ImageListSource source("folder", dir, FolderOptions(), GroundTruthOptions());
  ASSERT_TRUE(source.Open().ok());
  int bad = 0;
  const std::vector<Frame> frames = ReadAll(&source, &bad);
  EXPECT_EQ(bad, 2);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[1].index, 3);
}

TEST(ImageFolder, MissingOrEmptyFolderIsNotFound) {
  ImageListSource missing("folder", "/nonexistent/folder", FolderOptions(), GroundTruthOptions());
  EXPECT_EQ(missing.Open().kind(), SourceError::kNotFound);
  ImageListSource empty("folder", MakeTempDir("empty"), FolderOptions(), GroundTruthOptions());
  EXPECT_EQ(empty.Open().kind(), SourceError::kNotFound);
  ImageListSource no_input("folder", "", FolderOptions(), GroundTruthOptions());
  EXPECT_EQ(no_input.Open().kind(), SourceError::kConfig);
}

TEST(TumSequence, ImagesTimedByRgbTxtWithInterpolatedTruth) {
  const std::string dir = MakeTempDir("tum");
  fs::create_directories(dir + "/rgb");
  WriteTextFile(dir + "/rgb.txt",
                "# color images\n# file: 'x.bag'\n# timestamp filename\n"
                "1305031102.175304 rgb/1305031102.175304.png\n"
                "1305031102.211214 rgb/1305031102.211214.png\n"
                "1305031110.000000 rgb/1305031110.000000.png\n");
  for (const char* name : {"1305031102.175304", "1305031102.211214", "1305031110.000000"}) {
    cv::imwrite(dir + "/rgb/" + name + ".png", MakeTestImage(16, 12, 3, 1));
  }
  // Truth along x at 1 m/s, 100 Hz, from 1305031102.1 to 1305031103.0.
  std::string truth = "# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n";
  for (int i = 0; i <= 90; ++i) {
    const double t = 1305031102.1 + 0.01 * i;
    char line[128];
    std::snprintf(line, sizeof(line), "%.4f %.6f 0.5 1.0 0 0 0 1\n", t, 0.01 * i);
    truth += line;
  }
  WriteTextFile(dir + "/groundtruth.txt", truth);
  ImageListSource source("tum", dir, FolderOptions(), GroundTruthOptions());
  ASSERT_TRUE(source.Open().ok()) << source.Open().message();
  const std::vector<Frame> frames = ReadAll(&source);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0].utime, 1305031102175304);
  EXPECT_EQ(frames[1].utime, 1305031102211214);
  EXPECT_TRUE(frames[0].has_truth_source);
  EXPECT_EQ(frames[0].truth_source, "tum");
  ASSERT_TRUE(frames[0].world_from_cam.has_value());
  EXPECT_NEAR(frames[0].world_from_cam->translation.x(), 0.075304, 1e-9);
  EXPECT_NEAR(frames[1].world_from_cam->translation.x(), 0.111214, 1e-9);
  EXPECT_FALSE(frames[2].world_from_cam.has_value());  // after the truth ends
}

TEST(TumSequence, CutDownLayoutWithOneTruthLinePerImage) {
  const std::string dir = MakeTempDir("tumsub");
  fs::create_directories(dir + "/raw_imgs");
  for (int i = 0; i < 3; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%04d_rgb_raw.png", i);
    cv::imwrite(dir + "/raw_imgs/" + name, MakeTestImage(8, 6, 3, i));
  }
  WriteTextFile(dir + "/truth_cam_poses.txt",
                "100.5 1 2 3 0 0 0 1\n101.25 1 2 4 0 0 0 1\n102 1 2 5 0 0 0 1\n");
  ImageListSource source("tum", dir, FolderOptions(), GroundTruthOptions());
  ASSERT_TRUE(source.Open().ok());
  const std::vector<Frame> frames = ReadAll(&source);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[1].utime, 101250000);
  EXPECT_EQ(frames[2].world_from_cam->translation.z(), 5.0);
  WriteTextFile(dir + "/truth_cam_poses.txt", "100.5 1 2 3 0 0 0 1\n");
  ImageListSource mismatch("tum", dir, FolderOptions(), GroundTruthOptions());
  EXPECT_EQ(mismatch.Open().kind(), SourceError::kConfig);
}

TEST(Kitti, RawLayoutWithDateTimes) {
  const std::string dir = MakeTempDir("kitti_raw");
  fs::create_directories(dir + "/image_02/data");
  for (int i = 0; i < 2; ++i) {
    cv::imwrite(dir + "/image_02/data/" + testing_util::FrameName(i, ".png").insert(0, "0000"),
                MakeTestImage(12, 8, 3, i));
  }
  WriteTextFile(dir + "/image_02/timestamps.txt",
                "2011-09-26 13:02:25.964389445\n2011-09-26 13:02:26.068102373\n");
  ImageListSource source("kitti", dir, FolderOptions(), GroundTruthOptions());
  ASSERT_TRUE(source.Open().ok());
  const std::vector<Frame> frames = ReadAll(&source);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].utime, int64_t{1317042145} * 1000000 + 964389);
  EXPECT_EQ(frames[1].utime - frames[0].utime, 103713);
}

// Regression (issue 9): a 25-digit frame index made std::stoull throw out of the
// driver; out-of-range date fields overflowed year - 1900 and seconds * 1e6.
TEST(DatasetTimes, OutOfRangeFieldsAreConfigErrorsNotCrashes) {
  const std::string dir = MakeTempDir("stamps_range");
  for (int i = 0; i < 2; ++i) cv::imwrite(dir + "/" + std::to_string(i) + ".png", MakeTestImage(8, 8, 1, i));
  FolderOptions options;
  options.timestamps_file = dir + "/t.txt";
  for (const std::string& bad : {std::string("0 1\n1234567890123456789012345 2\n"),
                                 std::string("0 1\n4294967296 2\n")}) {
    WriteTextFile(options.timestamps_file, bad);
    ImageListSource folder("folder", dir, options, GroundTruthOptions());
    SourceStatus st;
    ASSERT_NO_THROW(st = folder.Open()) << bad;
    EXPECT_EQ(st.kind(), SourceError::kConfig) << bad;
  }

  // Found by fuzz_kitti_times: a times.txt line of separators only (",") threw
  // std::out_of_range out of IndexKitti.
  const std::string odo = MakeTempDir("kitti_comma") + "/sequences/00";
  fs::create_directories(odo + "/image_2");
  for (int i = 0; i < 2; ++i) cv::imwrite(odo + "/image_2/00000" + std::to_string(i) + ".png", MakeTestImage(8, 8, 1, i));
  WriteTextFile(odo + "/times.txt", "0.0\n,\n");
  {
    ImageListSource source("kitti", odo, FolderOptions(), GroundTruthOptions());
    SourceStatus st;
    ASSERT_NO_THROW(st = source.Open());
    EXPECT_EQ(st.kind(), SourceError::kConfig);
    EXPECT_NE(st.message().find("times.txt:2"), std::string::npos) << st.message();
  }

  const std::string kitti = MakeTempDir("kitti_range");
  fs::create_directories(kitti + "/image_02/data");
  for (int i = 0; i < 2; ++i) {
    cv::imwrite(kitti + "/image_02/data/" + testing_util::FrameName(i, ".png").insert(0, "0000"),
                MakeTestImage(12, 8, 3, i));
  }
  for (const std::string& bad :
       {std::string("-2147483648-01-01 00:00:00\n-2147483647-01-01 00:00:00\n"),
        std::string("2147483647-01-01 00:00:00\n2147483647-01-02 00:00:00\n"),
        std::string("2011-13-26 13:02:25\n2011-09-26 13:02:26\n"),
        std::string("2011-09-26 13:02:25.5e300\n2011-09-26 13:02:26\n")}) {
    WriteTextFile(kitti + "/image_02/timestamps.txt", bad);
    ImageListSource source("kitti", kitti, FolderOptions(), GroundTruthOptions());
    const SourceStatus st = source.Open();
    EXPECT_EQ(st.kind(), SourceError::kConfig) << bad;
  }
}

TEST(Kitti, OdometryLayoutWithTimesAndPoses) {
  const std::string root = MakeTempDir("kitti_odo");
  const std::string dir = root + "/sequences/07";
  fs::create_directories(dir + "/image_2");
  fs::create_directories(root + "/poses");
  for (int i = 0; i < 3; ++i) cv::imwrite(dir + "/image_2/" + testing_util::FrameName(i, ".png"), MakeTestImage(12, 8, 3, i));
  WriteTextFile(dir + "/times.txt", "0.000000e+00\n1.036594e-01\n2.073129e-01\n");
  WriteTextFile(root + "/poses/07.txt",
                "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 0.8\n1 0 0 0 0 1 0 0 0 0 1 1.6\n");
  ImageListSource source("kitti", dir, FolderOptions(), GroundTruthOptions());
  ASSERT_TRUE(source.Open().ok());
  const std::vector<Frame> frames = ReadAll(&source);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[1].utime, 103659);
  EXPECT_EQ(frames[2].truth_source, "kitti");
  EXPECT_EQ(frames[2].world_from_cam->translation.z(), 1.6);
}

TEST(TartanAir, TruthByFrameIndexInOpticalAxes) {
  const std::string dir = MakeTempDir("tartan");
  fs::create_directories(dir + "/image_left");
  for (int i = 0; i < 2; ++i) {
    cv::imwrite(dir + "/image_left/" + testing_util::FrameName(i, "_left.png"), MakeTestImage(8, 8, 3, i));
  }
  WriteTextFile(dir + "/pose_left.txt", "0 0 0 0 0 0 1\n1 0 0 0 0 0 1\n");
  FolderOptions options;
  options.rate_hz = 25.0;
  ImageListSource source("tartanair", dir, options, GroundTruthOptions());
  ASSERT_TRUE(source.Open().ok());
  const std::vector<Frame> frames = ReadAll(&source);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[1].utime, 40000);
  // Identity NED body: the camera looks along world x.
  EXPECT_LT((frames[1].world_from_cam->RotationMatrix().col(2) - Eigen::Vector3d::UnitX()).norm(), 1e-12);
  EXPECT_EQ(frames[1].world_from_cam->translation.x(), 1.0);
}

TEST(SimSequence, FramesTruthBodiesAndVisibility) {
  const std::string dir = MakeTempDir("seq") + "/street";
  testing_util::WriteSimSequence(dir, 6);
  ImageListSource source("sequence", dir, FolderOptions(), GroundTruthOptions());
  ASSERT_TRUE(source.Open().ok()) << source.Open().message();
  EXPECT_EQ(source.dataset_calibration_file(), dir + "/calibration.yaml");
  const std::vector<Frame> frames = ReadAll(&source);
  ASSERT_EQ(frames.size(), 6u);
  for (int i = 0; i < 6; ++i) {
    const Frame& f = frames[static_cast<size_t>(i)];
    EXPECT_EQ(f.utime, 1000000 + 50000 * i);
    EXPECT_TRUE(Identical(f.image, MakeTestImage(64, 48, 1, i)));
    EXPECT_EQ(f.truth_source, "sim:unit_test_street");
    ASSERT_TRUE(f.world_from_cam.has_value());
    EXPECT_NEAR(f.world_from_cam->translation.x(), 0.05 * i, 1e-12);
    ASSERT_EQ(f.bodies.size(), 1u);
    const BodyTruth& car = f.bodies[0];
    EXPECT_EQ(car.id, 1);
    EXPECT_EQ(car.name, "car");
    EXPECT_EQ(car.extent, Eigen::Vector3d(4.0, 1.8, 1.5));
    EXPECT_NEAR(car.world_from_body.translation.y(), 0.1 * i, 1e-12);
    EXPECT_NEAR(car.linear_velocity.y(), 2.0, 1e-9);     // 0.1 m per 50 ms
    EXPECT_NEAR(car.angular_velocity.z(), 2.0, 1e-9);    // 0.1 rad per 50 ms
    EXPECT_EQ(car.visible, i % 2 == 0) << i;
  }
}

TEST(SimSequence, BadTimestampsAreRejected) {
  const std::string dir = MakeTempDir("seqbad");
  testing_util::WriteSimSequence(dir, 3);
  WriteTextFile(dir + "/timestamps.txt", "0 100\n2 200\n");
  ImageListSource source("sequence", dir, FolderOptions(), GroundTruthOptions());
  EXPECT_EQ(source.Open().kind(), SourceError::kConfig);
  fs::remove(dir + "/timestamps.txt");
  EXPECT_EQ(source.Open().kind(), SourceError::kNotFound);
}

TEST(GroundTruthOverride, TumFileReplacesTheDatasetTruth) {
  const std::string dir = MakeTempDir("gtover");
  for (int i = 0; i < 3; ++i) cv::imwrite(dir + "/" + std::to_string(i) + ".png", MakeTestImage(8, 8, 1, i));
  WriteTextFile(dir + "/truth.tum", "0.0 0 0 0 0 0 0 1\n0.15 3 0 0 0 0 0 1\n");
  FolderOptions folder;
  folder.rate_hz = 10.0;
  GroundTruthOptions truth;
  truth.file = dir + "/truth.tum";
  truth.max_gap_s = 0.2;
  ImageListSource source("folder", dir, folder, truth);
  ASSERT_TRUE(source.Open().ok());
  const std::vector<Frame> frames = ReadAll(&source);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_NEAR(frames[1].world_from_cam->translation.x(), 2.0, 1e-12);  // 0.1 s of 0.15
  EXPECT_FALSE(frames[2].world_from_cam.has_value());                 // 0.2 s: after the last
  EXPECT_TRUE(frames[2].has_truth_source);
}

// The real data sets, when present (../shared/data relative to the repo root).
std::string SharedData(const std::string& sub) {
  for (const char* base : {"../shared/data/", "/work/shared/data/"}) {
    if (fs::exists(std::string(base) + sub)) return std::string(base) + sub;
  }
  return "";
}

TEST(RealData, TumCabinetSubset) {
  const std::string dir = SharedData("tum_fr3_cabinet_subset");
  if (dir.empty()) GTEST_SKIP() << "tum_fr3_cabinet_subset not present";
  ImageListSource source("tum", dir, FolderOptions(), GroundTruthOptions());
  ASSERT_TRUE(source.Open().ok());
  EXPECT_EQ(source.num_frames(), 58);
  Frame f;
  SourceStatus st;
  ASSERT_EQ(source.Next(&f, &st), FrameSource::ReadResult::kFrame);
  EXPECT_EQ(f.utime, 1341841278842700);
  EXPECT_EQ(f.image.cols, 640);
  EXPECT_EQ(f.image.rows, 480);
  ASSERT_TRUE(f.world_from_cam.has_value());
  EXPECT_NEAR(f.world_from_cam->translation.x(), -2.5508, 1e-12);
  EXPECT_FALSE(f.file_bytes.empty());  // a JPEG passed through unchanged
}

TEST(RealData, TartanAirSubset) {
  const std::string dir = SharedData("tartanair_indoor_subset");
  if (dir.empty()) GTEST_SKIP() << "tartanair_indoor_subset not present";
  ImageListSource source("tartanair", dir, FolderOptions(), GroundTruthOptions());
  ASSERT_TRUE(source.Open().ok());
  EXPECT_EQ(source.num_frames(), 189);
  Frame f;
  SourceStatus st;
  ASSERT_EQ(source.Next(&f, &st), FrameSource::ReadResult::kFrame);
  EXPECT_EQ(f.image.cols, 640);
  ASSERT_TRUE(f.world_from_cam.has_value());
}

TEST(RealData, DavisAndCamVidFolders) {
  for (const char* sub : {"davis2016/JPEGImages/blackswan", "camvid_0016E5_15hz/images"}) {
    const std::string dir = SharedData(sub);
    if (dir.empty()) continue;
    ImageListSource source("folder", dir, FolderOptions(), GroundTruthOptions());
    ASSERT_TRUE(source.Open().ok()) << sub;
    EXPECT_GT(source.num_frames(), 40) << sub;
    int bad = 0;
    EXPECT_EQ(static_cast<int64_t>(ReadAll(&source, &bad).size()), source.num_frames());
    EXPECT_EQ(bad, 0);
  }
}

}  // namespace
}  // namespace mbslam
