// planner_example: is a timed path free over the next second? Subscribes to the
// perception service's PERCEPTION_OCCUPANCY (OctoMap binary of the static world) and
// PERCEPTION_OBJECTS (moving objects with predicted volumes), live or from a log, and
// checks a path against both. The integration recipe for planners is README.md here.
//
//   planner_example --lcm-url 'file://run.lcmlog?speed=0' --waypoints '0 0 0 0; 1 1 0 0'
//   planner_example --lcm-url udpm://239.255.76.67:7667?ttl=0 --path path.txt --watch
//
// Exit status: 0 free, 1 blocked, 2 no perception data or bad input.

#include <octomap/OcTree.h>

#include <chrono>
#include <cstdio>
#include <exception>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "common/config/options_yaml.h"
#include "common/lcm/channels.h"
#include "common/lcm/lcm_bus.h"
#include "common/lcm/wire_check.h"
#include "common/util/atomic_file.h"
#include "common/util/command_line.h"
#include "common/util/shutdown.h"
#include "mbslam/camera_pose_t.hpp"
#include "mbslam/objects_t.hpp"
#include "mbslam/occupancy_t.hpp"
#include "services/perception/occupancy/octree_io.h"
#include "tools/planner_example/path_checker.h"

namespace {

using mbslam::Status;
namespace planner = mbslam::planner;

constexpr int kExitFree = 0;
constexpr int kExitBlocked = 1;
constexpr int kExitNoAnswer = 2;
// An occupancy message larger than this is dropped undecoded. ReadOctreeBinary's node
// bound (8 M nodes) needs at most 16 MB of node data.
constexpr size_t kMaxOccupancyBytes = size_t{64} << 20;

constexpr char kUsage[] =
    "usage: planner_example --lcm-url URL (--path FILE | --waypoints 't x y z; ...')\n"
    "         [--robot-radius R] [--horizon S] [--unknown-is-occupied] [--min-probability P]\n"
    "         [--no-hold] [--watch] [--period S] [--wait S] [--require-metric]\n"
    "         [--occupancy-channel NAME] [--objects-channel NAME] [--print-config]\n"
    "  --lcm-url        memq://, udpm://...?ttl=0 (live) or file://LOG?speed=0 (a log, read to its "
    "end)\n"
    "  --path           waypoints 't x y z' per line (t in s after the latest estimate; x y z\n"
    "                   in the world frame, m or map units); '-' reads stdin\n"
    "  --waypoints      the same on the command line, waypoints separated by ';'\n"
    "  --robot-radius   radius of the robot's sphere (default 0.3, world units)\n"
    "  --horizon        seconds of the path checked (default 1.0)\n"
    "  --unknown-is-occupied  never-observed voxels block too\n"
    "  --min-probability      ignore predicted volumes below this probability\n"
    "  --no-hold        do not check the robot at rest at its last waypoint until the horizon\n"
    "  --watch          answer for every new PERCEPTION_OBJECTS, at most every --period\n"
    "                   seconds of message time (default 0.5), until Ctrl-C or the end of\n"
    "                   the log; lines '<utime> free|blocked by ...'; exits with the status\n"
    "                   of the last answer\n"
    "  --wait           live: seconds to wait for the first messages (default 3)\n"
    "  --require-metric refuse a world that is only up to scale\n"
    "exit status: 0 free, 1 blocked, 2 no perception data or bad input\n";

// The latest perception outputs, decoded.
struct PerceptionState {
  std::shared_ptr<const octomap::OcTree> tree;
  int64_t occupancy_utime = -1;
  int8_t occupancy_scale = -1;  // camera_pose_t.SCALE_*
  std::vector<planner::MovingObstacle> obstacles;
  int64_t objects_utime = -1;
  int8_t objects_scale = -1;
  bool new_objects = false;
  int bad_messages = 0;

  bool HasData() const { return tree != nullptr || objects_utime >= 0; }
  // "Now": the time of the objects' estimate (their volumes are relative to it), else
  // the occupancy's.
  int64_t NowUtime() const { return objects_utime >= 0 ? objects_utime : occupancy_utime; }
};

Eigen::Quaterniond Quaternion(const double wxyz[4]) {
  Eigen::Quaterniond q(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  if (!(q.norm() > 1e-9) || !q.coeffs().allFinite()) {
    return Eigen::Quaterniond::Identity();
  }
  return q.normalized();
}

void OnOccupancy(const uint8_t* data, size_t size, PerceptionState* state) {
  mbslam::occupancy_t msg{};
  Status st = mbslam::DecodeLcmMessage(data, size, &msg, kMaxOccupancyBytes);
  std::unique_ptr<octomap::OcTree> tree;
  if (st.ok()) {
    // Bounds-checked: octomap's own readBinary trusts the stream (depth, length, size).
    st = mbslam::ReadOctreeBinary(msg.data.data(), msg.data.size(), mbslam::OctreeReadLimits(),
                                  &tree);
  }
  if (!st.ok()) {
    ++state->bad_messages;
    std::cerr << "planner_example: dropped an occupancy message: " << st.message() << "\n";
    return;
  }
  state->tree = std::move(tree);
  state->occupancy_utime = msg.utime;
  state->occupancy_scale = msg.scale_state;
}

void OnObjects(const uint8_t* data, size_t size, PerceptionState* state) {
  mbslam::objects_t msg{};
  const Status st = mbslam::DecodeLcmMessage(data, size, &msg);
  if (!st.ok()) {
    ++state->bad_messages;
    std::cerr << "planner_example: dropped an objects message: " << st.message() << "\n";
    return;
  }
  std::vector<planner::MovingObstacle> obstacles;
  for (const mbslam::object_t& o : msg.objects) {
    planner::MovingObstacle obstacle;
    obstacle.id = o.id;
    for (const mbslam::predicted_volume_t& v : o.volumes) {
      planner::OrientedBox box;
      box.utime = v.utime;
      box.center = Eigen::Vector3d(v.center[0], v.center[1], v.center[2]);
      box.orientation = Quaternion(v.orientation);
      box.half_extent = Eigen::Vector3d(v.half_extent[0], v.half_extent[1], v.half_extent[2]);
      box.probability = v.probability;
      if (box.center.allFinite() && box.half_extent.allFinite()) {
        obstacle.volumes.push_back(box);
      }
    }
    if (obstacle.volumes.empty()) {
      // No prediction: the object's current box, assumed to stay where it is.
      planner::OrientedBox box;
      box.utime = msg.utime;
      box.center = Eigen::Vector3d(o.position[0], o.position[1], o.position[2]);
      box.orientation = Quaternion(o.orientation);
      box.half_extent = 0.5 * Eigen::Vector3d(o.extent[0], o.extent[1], o.extent[2]);
      if (box.center.allFinite() && box.half_extent.allFinite()) {
        obstacle.volumes.push_back(box);
      }
    }
    obstacles.push_back(std::move(obstacle));
  }
  state->obstacles = std::move(obstacles);
  state->objects_utime = msg.utime;
  state->objects_scale = msg.scale_state;
  state->new_objects = true;
}

// Checks the path against the current state; prints the answer. Returns the exit code.
int Answer(const PerceptionState& state, const planner::PathCheckOptions& options,
           const std::vector<planner::Waypoint>& path, bool require_metric, bool watch) {
  if (!state.HasData()) {
    std::cerr << "planner_example: no perception data (" << state.bad_messages
              << " bad messages)\n";
    return kExitNoAnswer;
  }
  const bool up_to_scale =
      (state.tree && state.occupancy_scale != mbslam::camera_pose_t::SCALE_METRIC) ||
      (state.objects_utime >= 0 && state.objects_scale != mbslam::camera_pose_t::SCALE_METRIC);
  if (up_to_scale) {
    if (require_metric) {
      std::cerr << "planner_example: the world is only up to scale (no odometry): refused\n";
      return kExitNoAnswer;
    }
    std::cerr << "planner_example: note: the world is up to scale, path and radius are taken "
                 "in map units\n";
  }
  if (!state.tree) {
    std::cerr << "planner_example: note: no occupancy received, static obstacles not checked\n";
  }
  planner::PathChecker checker(options);
  checker.SetOccupancy(state.tree);
  checker.SetObstacles(state.obstacles);
  planner::PathConflict conflict;
  planner::PathCheckSummary summary;
  const Status st = checker.Check(path, state.NowUtime(), &conflict, &summary);
  if (!st.ok()) {
    std::cerr << "planner_example: " << st.message() << "\n";
    return kExitNoAnswer;
  }
  if (watch) {
    std::cout << state.NowUtime() << " ";
  }
  std::cout << conflict.Describe() << std::endl;
  return conflict.blocked() ? kExitBlocked : kExitFree;
}

int Run(int argc, char** argv) {
  const mbslam::CommandLineArgs args(argc, argv);
  if (argc == 1 || args.Has("help")) {
    std::cout << kUsage;
    return argc == 1 ? kExitNoAnswer : kExitFree;
  }
  planner::PathCheckOptions options;
  double period_s = 0.5, wait_s = 3.0;
  options.robot_radius = args.GetDouble("robot-radius", options.robot_radius);
  options.horizon_s = args.GetDouble("horizon", options.horizon_s);
  options.min_volume_probability = args.GetDouble("min-probability", options.min_volume_probability);
  period_s = args.GetDouble("period", period_s);
  wait_s = args.GetDouble("wait", wait_s);
  options.unknown_is_occupied = args.Has("unknown-is-occupied");
  options.hold_last_waypoint = !args.Has("no-hold");
  const bool watch = args.Has("watch");
  const bool require_metric = args.Has("require-metric");
  const bool print_config = args.Has("print-config");
  mbslam::ChannelOptions channels;
  const std::string occupancy_channel =
      args.Get("occupancy-channel", channels.perception_occupancy);
  const std::string objects_channel = args.Get("objects-channel", channels.perception_objects);
  const std::string url = args.Get("lcm-url");
  const std::string path_file = args.Get("path");
  const std::string waypoints = args.Get("waypoints");
  const std::string problems = args.Problems();
  if (!problems.empty()) {
    std::cerr << "planner_example: " << problems << "\n" << kUsage;
    return kExitNoAnswer;
  }
  if (!options.Check()) {
    std::cerr << "planner_example: " << mbslam::LastOptionError() << "\n";
    return kExitNoAnswer;
  }
  if (print_config) {
    std::cout << mbslam::OptionsToYaml(options);
    return kExitFree;
  }
  if (url.empty() || (path_file.empty() == waypoints.empty())) {
    std::cerr << "planner_example: give --lcm-url and one of --path / --waypoints\n" << kUsage;
    return kExitNoAnswer;
  }
  std::string path_text = waypoints;
  if (!path_file.empty()) {
    if (path_file == "-") {
      std::ostringstream in;
      in << std::cin.rdbuf();
      path_text = in.str();
    } else {
      const Status st = mbslam::ReadFileToString(path_file, &path_text);
      if (!st.ok()) {
        std::cerr << "planner_example: " << st.message() << "\n";
        return kExitNoAnswer;
      }
    }
  }
  std::vector<planner::Waypoint> path;
  Status st = planner::ParsePath(path_text, &path);
  if (!st.ok()) {
    std::cerr << "planner_example: " << st.message() << "\n";
    return kExitNoAnswer;
  }

  std::unique_ptr<mbslam::LcmBus> bus = mbslam::LcmBus::Create(url, &st);
  if (!bus) {
    std::cerr << "planner_example: " << st.message() << "\n";
    return kExitNoAnswer;
  }
  PerceptionState state;
  bus->Subscribe(
      occupancy_channel,
      [&state](const std::string&, const uint8_t* data, size_t size, int64_t) {
        OnOccupancy(data, size, &state);
      },
      2);
  bus->Subscribe(
      objects_channel,
      [&state](const std::string&, const uint8_t* data, size_t size, int64_t) {
        OnObjects(data, size, &state);
      },
      10);
  mbslam::InstallShutdownHandlers();
  const bool from_log = url.rfind("file://", 0) == 0;
  const auto start = std::chrono::steady_clock::now();
  auto waited_s = [&start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };

  int code = kExitNoAnswer;
  int64_t last_answer_utime = INT64_MIN;
  while (!mbslam::ShutdownRequested()) {
    const int handled = bus->HandleTimeout(100);
    if (handled < 0) {
      break;  // end of the log (or a bus error)
    }
    if (watch) {
      // In watch mode: one answer per new PERCEPTION_OBJECTS (published for every
      // processed image, with or without objects), at most every `period_s` of message
      // time. The occupancy is used as it arrives.
      if (state.new_objects &&
          state.NowUtime() >= last_answer_utime + static_cast<int64_t>(period_s * 1e6)) {
        code = Answer(state, options, path, require_metric, /*watch=*/true);
        last_answer_utime = state.NowUtime();
      }
      state.new_objects = false;
      continue;
    }
    if (!from_log && ((state.tree && state.objects_utime >= 0) || waited_s() > wait_s)) {
      break;  // live: have both (or waited long enough)
    }
  }
  if (!watch) {
    code = Answer(state, options, path, require_metric, /*watch=*/false);
  }
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "planner_example: unexpected error: " << e.what() << "\n";
    return kExitNoAnswer;
  }
}
