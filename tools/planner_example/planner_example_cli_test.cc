// planner_example end to end on a synthetic log (file:// only): an occupancy_t built
// from an OcTree with a wall, and objects_t with a crossing object's predicted volumes.

#include <gtest/gtest.h>
#include <octomap/OcTree.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "common/lcm/channels.h"
#include "common/lcm/lcm_log.h"
#include "common/util/atomic_file.h"
#include "mbslam/camera_pose_t.hpp"
#include "mbslam/objects_t.hpp"
#include "mbslam/occupancy_t.hpp"
#include "test/tools/run_command.h"

namespace mbslam {
namespace {

namespace fs = std::filesystem;

constexpr int64_t kStart = 1600000000000000;

std::string Bin() { return testing_util::ToolPath("planner_example"); }

// Runs the executable; returns its exit status and its stdout.
int RunPlanner(const std::string& args, std::string* out) {
  return testing_util::RunCommand(Bin() + " " + args + " 2>/dev/null", out);
}

// The static world: a wall x in [2.0, 2.1], y in [-1, 1], z in [0, 2], metres.
mbslam::occupancy_t Occupancy(int64_t utime) {
  octomap::OcTree tree(0.1);
  for (int j = -10; j < 10; ++j) {
    for (int k = 0; k < 20; ++k) {
      for (int i = 0; i < 20; ++i) {
        tree.updateNode(0.1 * i + 0.05, 0.1 * j + 0.05, 0.1 * k + 0.05, false);
      }
      tree.updateNode(2.05, 0.1 * j + 0.05, 0.1 * k + 0.05, true);
    }
  }
  std::ostringstream binary;
  EXPECT_TRUE(tree.writeBinary(binary));
  const std::string data = binary.str();
  mbslam::occupancy_t m{};
  m.utime = utime;
  m.frame_id = "world";
  m.scale_state = mbslam::camera_pose_t::SCALE_METRIC;
  m.resolution = 0.1;
  m.num_occupied = 200;
  m.size = static_cast<int32_t>(data.size());
  m.data.assign(data.begin(), data.end());
  return m;
}

// Object 7, a 1 m box crossing x = 5 along +y at 4 m/s, at y = 0 half a second after
// the estimate at `utime` (estimates every 100 ms keep that crossing time fixed).
mbslam::objects_t Objects(int64_t utime, int64_t crossing_utime) {
  mbslam::objects_t m{};
  m.utime = utime;
  m.scale_state = mbslam::camera_pose_t::SCALE_METRIC;
  mbslam::object_t o{};
  o.id = 7;
  o.state = mbslam::object_t::STATE_TRACKED;
  o.orientation[0] = 1.0;
  for (int i = 0; i < 3; ++i) {
    o.extent[i] = 1.0;
  }
  for (int h = 0; h <= 4; ++h) {
    mbslam::predicted_volume_t v{};
    v.horizon_us = int64_t{250000} * h;
    v.utime = utime + v.horizon_us;
    const double dt = 1e-6 * static_cast<double>(v.utime - crossing_utime);
    v.center[0] = 5.0;
    v.center[1] = 4.0 * dt;
    v.center[2] = 0.5;
    v.orientation[0] = 1.0;
    for (int i = 0; i < 3; ++i) {
      v.half_extent[i] = 0.5 + 0.1 * h;  // grows with the horizon
    }
    v.probability = 0.9;
    o.volumes.push_back(v);
  }
  o.position[0] = o.volumes[0].center[0];
  o.position[1] = o.volumes[0].center[1];
  o.position[2] = o.volumes[0].center[2];
  o.num_volumes = static_cast<int32_t>(o.volumes.size());
  m.objects.push_back(o);
  m.num_objects = 1;
  return m;
}

class PlannerExampleCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(Bin())) {
      GTEST_SKIP() << Bin() << " not built";
    }
    dir_ = fs::temp_directory_path() / ("mbslam_planner_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    log_ = (dir_ / "perception.lcmlog").string();
    ChannelOptions channels;
    Status st;
    auto writer = LcmLogWriter::Open(log_, &st);
    ASSERT_TRUE(writer) << st.message();
    // Three estimates 100 ms apart; the occupancy with the first. The last estimate is
    // "now": the object crosses y = 0 at x = 5 half a second later.
    const int64_t crossing = kStart + 200000 + 500000;
    for (int f = 0; f < 3; ++f) {
      const int64_t utime = kStart + int64_t{100000} * f;
      if (f == 0) {
        ASSERT_TRUE(writer->Write(channels.perception_occupancy, utime, Occupancy(utime)).ok());
      }
      ASSERT_TRUE(writer->Write(channels.perception_objects, utime, Objects(utime, crossing)).ok());
    }
    writer->Flush();
  }
  void TearDown() override {
    if (!dir_.empty()) {
      fs::remove_all(dir_);
    }
  }
  std::string Url() const { return "'file://" + log_ + "?speed=0'"; }

  fs::path dir_;
  std::string log_;
};

TEST_F(PlannerExampleCli, PathThroughTheWallIsBlocked) {
  std::string out;
  EXPECT_EQ(RunPlanner("--lcm-url " + Url() + " --waypoints '0 0 0.05 1; 1 4 0.05 1'", &out), 1);
  EXPECT_EQ(out.rfind("blocked by occupied voxel at (2.05", 0), 0u) << out;
}

TEST_F(PlannerExampleCli, PathAroundTheWallIsFree) {
  std::string out;
  EXPECT_EQ(RunPlanner("--lcm-url " + Url() + " --waypoints '0 0 2 1; 1 3 2 1'", &out), 0);
  EXPECT_EQ(out, "free\n");
  // The same from a file.
  ASSERT_TRUE(
      WriteStringAtomically((dir_ / "path.txt").string(), "# t x y z\n0 0 2 1\n1 3 2 1\n").ok());
  EXPECT_EQ(RunPlanner("--lcm-url " + Url() + " --path " + (dir_ / "path.txt").string(), &out), 0);
  EXPECT_EQ(out, "free\n");
}

TEST_F(PlannerExampleCli, PathAcrossTheMovingObjectIsBlocked) {
  std::string out;
  // Beside the wall, reaching x = 5 at t = 0.5 s when the object crosses y = 0 there.
  EXPECT_EQ(RunPlanner("--lcm-url " + Url() + " --waypoints '0 2.5 0 0.5; 1 7.5 0 0.5'", &out), 1);
  EXPECT_EQ(out.rfind("blocked by object 7", 0), 0u) << out;
  // The same motion 3 m beside the crossing point: free.
  EXPECT_EQ(RunPlanner("--lcm-url " + Url() + " --waypoints '0 2.5 3 0.5; 1 7.5 3 0.5'", &out), 0)
      << out;
  // A smaller robot still hits it (the volumes are 1 m boxes and more).
  EXPECT_EQ(RunPlanner("--lcm-url " + Url() +
                           " --robot-radius 0.05 --waypoints '0 2.5 0 0.5; 1 7.5 0 0.5'",
                       &out),
            1);
}

TEST_F(PlannerExampleCli, WatchAnswersEveryEstimate) {
  std::string out;
  EXPECT_EQ(
      RunPlanner("--lcm-url " + Url() + " --watch --period 0 --waypoints '0 0 2 1; 1 3 2 1'", &out),
      0);
  EXPECT_EQ(out, std::to_string(kStart) + " free\n" + std::to_string(kStart + 100000) + " free\n" +
                     std::to_string(kStart + 200000) + " free\n");
  // At most one answer per 0.15 s of message time.
  EXPECT_EQ(
      RunPlanner("--lcm-url " + Url() + " --watch --period 0.15 --waypoints '0 0 2 1; 1 3 2 1'",
                 &out),
      0);
  EXPECT_EQ(out, std::to_string(kStart) + " free\n" + std::to_string(kStart + 200000) + " free\n");
}

TEST_F(PlannerExampleCli, NoDataOrBadInput) {
  std::string out;
  const std::string empty = (dir_ / "empty.lcmlog").string();
  {
    Status st;
    auto writer = LcmLogWriter::Open(empty, &st);
    ASSERT_TRUE(writer);
  }
  EXPECT_EQ(RunPlanner("--lcm-url 'file://" + empty + "?speed=0' --waypoints '0 0 0 0'", &out), 2);
  EXPECT_EQ(RunPlanner("--lcm-url " + Url() + " --waypoints '0 0 0'", &out), 2);
  EXPECT_EQ(RunPlanner("--lcm-url " + Url(), &out), 2);
  EXPECT_EQ(RunPlanner("--lcm-url " + Url() + " --waypoints '0 0 2 1' --bogus", &out), 2);
  // A malformed number is bad input, not its default.
  EXPECT_EQ(RunPlanner("--lcm-url " + Url() + " --waypoints '0 0 2 1' --robot-radius 0.3m", &out), 2);
  EXPECT_EQ(RunPlanner("--lcm-url " + Url() + " --waypoints '0 0 2 1' --horizon nan", &out), 2);
  EXPECT_EQ(RunPlanner("--lcm-url " + Url() + " --waypoints '0 0 2 1' --require-metric", &out), 0);
  // An up-to-scale world: answered in map units, or refused on request.
  const std::string uts = (dir_ / "up_to_scale.lcmlog").string();
  {
    Status st;
    auto writer = LcmLogWriter::Open(uts, &st);
    ASSERT_TRUE(writer);
    mbslam::objects_t objects = Objects(kStart, kStart + 500000);
    objects.scale_state = mbslam::camera_pose_t::SCALE_UP_TO_SCALE;
    ASSERT_TRUE(writer->Write(ChannelOptions().perception_objects, kStart, objects).ok());
  }
  EXPECT_EQ(RunPlanner("--lcm-url 'file://" + uts + "?speed=0' --waypoints '0 0 2 1'", &out), 0);
  EXPECT_EQ(
      RunPlanner("--lcm-url 'file://" + uts + "?speed=0' --waypoints '0 0 2 1' --require-metric",
                 &out),
      2);
  EXPECT_EQ(RunPlanner("--print-config", &out), 0);
  EXPECT_NE(out.find("robot_radius: 0.3"), std::string::npos) << out;
}

}  // namespace
}  // namespace mbslam
