#include "services/perception/pipeline/result_recorder.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <sstream>
#include <string>
#include <vector>

#include "common/testing/temp_dir.h"
#include "common/util/atomic_file.h"

namespace mbslam {
namespace {

// Image i (at 1 s + i * 0.1 s) with a camera pose in `state`, its x = i.
FrameResult ImageResult(int i, TrackingState state) {
  FrameResult r;
  r.utime = 1000000 + i * 100000;
  r.camera_pose.utime = r.utime;
  r.camera_pose.tracking_state = state;
  r.camera_pose.world_from_cam.translation.x() = i;
  return r;
}

// The x of every pose of a TUM file, in order.
std::vector<double> TrajectoryX(const std::string& path) {
  std::string text;
  EXPECT_TRUE(ReadFileToString(path, &text).ok()) << path;
  std::istringstream in(text);
  std::string line;
  std::vector<double> x;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double t, tx;
    fields >> t >> tx;
    x.push_back(tx);
  }
  return x;
}

TEST(ResultRecorder, TumLineFormat) {
  Rigid3d pose(Eigen::Quaterniond(1, 0, 0, 0), Eigen::Vector3d(1.5, -2, 3));
  EXPECT_EQ(TumLine(1234567890, pose),
            "1234.567890 1.500000000 -2.000000000 3.000000000 0.000000000 0.000000000 0.000000000 1.000000000");
}

TEST(ResultRecorder, WritesTrackedPosesAndSummary) {
  ResultRecorder recorder;
  for (int i = 0; i < 4; ++i) {
    FrameResult r = ImageResult(i, i == 0 ? TrackingState::kInitializing : TrackingState::kOk);
    recorder.OnFrameResult(r);
  }
  const std::string dir = testing_util::MakeTestTempDir("rec");
  ASSERT_TRUE(recorder.Write(dir, "\"note\": 1").ok());
  std::string traj, summary;
  ASSERT_TRUE(ReadFileToString(dir + "/camera_trajectory.tum", &traj).ok());
  ASSERT_TRUE(ReadFileToString(dir + "/summary.json", &summary).ok());
  int lines = 0;
  for (char c : traj) lines += c == '\n';
  EXPECT_EQ(lines, 4);  // header + 3 tracked
  EXPECT_NE(summary.find("\"tracked_fraction\": 0.75"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"note\": 1"), std::string::npos);
}

TEST(ResultRecorder, BackfilledPosesGoInTimeOrder) {
  ResultRecorder recorder;
  // Images 0-3 without a pose; image 4 confirms a map and brings poses for 0-3 (1 lost).
  for (int i = 0; i < 6; ++i) {
    FrameResult r = ImageResult(i, i < 4 ? TrackingState::kInitializing : TrackingState::kOk);
    if (i == 4) {
      for (int k : {0, 2, 3}) {
        Rigid3d p;
        p.translation.x() = k;
        r.backfilled_camera_poses.emplace_back(1000000 + k * 100000, p);
      }
    }
    if (i == 5) {  // a repeated image is not written twice
      r.backfilled_camera_poses.emplace_back(1000000 + 3 * 100000, Rigid3d());
    }
    recorder.OnFrameResult(r);
  }
  const std::string dir = testing_util::MakeTestTempDir("rec");
  ASSERT_TRUE(recorder.Write(dir, "").ok());
  std::string summary;
  ASSERT_TRUE(ReadFileToString(dir + "/summary.json", &summary).ok());
  EXPECT_EQ(TrajectoryX(dir + "/camera_trajectory.tum"), (std::vector<double>{0, 2, 3, 4, 5}));
  EXPECT_NE(summary.find("\"tracked_fraction\": 0.333"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"frames_backfilled\": 3"), std::string::npos) << summary;
}

// The camera poses as the map finally has them replace the published ones of the same
// images in camera_trajectory.tum; camera_trajectory_live.tum keeps what was published;
// poses of images the recorder never had a pose for are not added.
TEST(ResultRecorder, AdjustedPosesReplaceLiveOnesOfTheSameImages) {
  ResultRecorder recorder;
  for (int i = 0; i < 5; ++i) {
    FrameResult r = ImageResult(i, i == 1 ? TrackingState::kLost : TrackingState::kOk);
    recorder.OnFrameResult(r);
  }
  std::vector<std::pair<int64_t, Rigid3d>> adjusted;
  for (int i : {1, 2, 4, 7}) {  // 1: lost live, 7: never seen
    Rigid3d p;
    p.translation.x() = 10 + i;
    adjusted.emplace_back(1000000 + i * 100000, p);
  }
  recorder.OnAdjustedCameraTrajectory(adjusted);
  const std::string dir = testing_util::MakeTestTempDir("rec");
  ASSERT_TRUE(recorder.Write(dir, "").ok());
  EXPECT_EQ(TrajectoryX(dir + "/camera_trajectory.tum"), (std::vector<double>{0, 12, 3, 14}));
  EXPECT_EQ(TrajectoryX(dir + "/camera_trajectory_live.tum"), (std::vector<double>{0, 2, 3, 4}));
  std::string summary;
  ASSERT_TRUE(ReadFileToString(dir + "/summary.json", &summary).ok());
  EXPECT_NE(summary.find("\"frames_adjusted\": 2"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"tracked_fraction\": 0.8"), std::string::npos) << summary;
}

TEST(ResultRecorder, TrajectoriesAreBoundedOldestDropped) {
  ResultRecorder recorder(/*max_poses=*/10);
  for (int i = 0; i < 25; ++i) {
    FrameResult r = ImageResult(i, TrackingState::kOk);
    ObjectOutput o;
    o.id = 1 + i / 5;  // five poses per object
    o.state = ObjectState::kTracked;
    r.objects.push_back(o);
    recorder.OnFrameResult(r);
  }
  const std::string dir = testing_util::MakeTestTempDir("rec");
  ASSERT_TRUE(recorder.Write(dir, "").ok());
  std::string traj, summary, first_object;
  ASSERT_TRUE(ReadFileToString(dir + "/camera_trajectory.tum", &traj).ok());
  ASSERT_TRUE(ReadFileToString(dir + "/summary.json", &summary).ok());
  int lines = 0;
  for (char c : traj) lines += c == '\n';
  EXPECT_EQ(lines, 11);  // header + the newest 10
  EXPECT_NE(traj.find("\n2.500000 15.0"), std::string::npos) << traj;  // the oldest kept
  EXPECT_NE(summary.find("\"camera_poses_dropped\": 15"), std::string::npos) << summary;
  // Objects 1-3 (15 poses) dropped whole to get back to 10.
  EXPECT_NE(summary.find("\"object_poses_dropped\": 15"), std::string::npos) << summary;
  EXPECT_FALSE(ReadFileToString(dir + "/objects/3.tum", &first_object).ok());
  EXPECT_TRUE(ReadFileToString(dir + "/objects/4.tum", &first_object).ok());
  EXPECT_NE(summary.find("\"frames\": 25"), std::string::npos);
}

// What the recorder reports holding grows with what it keeps (camera and object poses,
// reconstructions' poses and points) and falls when the pose budget drops the oldest.
TEST(ResultRecorder, ReportsWhatItKeeps) {
  ResultRecorder recorder(/*max_poses=*/100);
  EXPECT_EQ(recorder.RetainedBytes(), 0);
  // Image i: a reconstruction of object 1 + i / 10 with 500 points, and a camera pose.
  auto image = [](int i, bool tracked) {
    FrameResult r = ImageResult(i, tracked ? TrackingState::kOk : TrackingState::kLost);
    ObjectReconstructionOutput rec;
    rec.object_id = 1 + i / 10;
    rec.map_id = rec.object_id;
    rec.points_included = true;
    rec.points.assign(500, Eigen::Vector3f::Ones());
    r.object_reconstructions.push_back(rec);
    return r;
  };
  int64_t last = 0;
  for (int i = 0; i < 40; ++i) {
    recorder.OnFrameResult(image(i, true));
    const int64_t now = recorder.RetainedBytes();
    EXPECT_GE(now, last) << i;
    last = now;
  }
  // 40 camera poses, 40 reconstruction poses and four reconstructions' 500 points each.
  EXPECT_GE(last, 80 * 64 + 4 * 500 * 12);
  EXPECT_LT(last, 2 * (80 * 64 + 4 * 500 * 12));
  // Past the budget (100 object poses), the oldest reconstructions go whole.
  for (int i = 40; i < 200; ++i) recorder.OnFrameResult(image(i, false));
  EXPECT_LT(recorder.RetainedBytes(), 40 * 64 + 100 * 64 * 2 + 11 * (500 * 12 + 256));
}

}  // namespace
}  // namespace mbslam
