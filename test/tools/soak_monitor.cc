// Samples a running perception_service for the soak test: its resident memory (from
// /proc/PID/status) and, from its LCM outputs, frames and map size. One CSV line per
// interval on stdout:
//   t_s,rss_mb,frames_received,frames_processed,frames_dropped,map_points,map_keyframes,map_observations,
//   occupancy_bytes,occupancy_mem_bytes,trajectory_poses,heap_in_use_mb,heap_held_mb,results_kept_mb
// map_observations sums keyframe_t.num_observations (point observations held by keyframes).
// trajectory_poses counts what the service keeps for its trajectory files: tracked camera
// poses plus tracked / reconstructed object poses (ResultRecorder, 64 B each).
// occupancy_mem_bytes is the service's estimate of its own probabilistic tree
// (occupancy_t.memory_bytes), the memory occupancy.max_memory_mb bounds.
//
//   soak_monitor --url URL --pid PID --seconds S [--interval S]
//
// Ends after S seconds or when the process is gone (exit 0), 2 on bad arguments.

#include <signal.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <string>


#include "common/lcm/channels.h"
#include "common/lcm/lcm_bus.h"
#include "common/lcm/wire_check.h"
#include "common/util/time.h"
#include "common/util/command_line.h"
#include "mbslam/camera_pose_t.hpp"
#include "mbslam/map_t.hpp"
#include "mbslam/objects_t.hpp"
#include "mbslam/occupancy_t.hpp"
#include "mbslam/status_t.hpp"

namespace {

// VmRSS in MB, or -1 when the process is gone.
double RssMb(int pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;
  }
  return -1.0;
}

}  // namespace

int main(int argc, char** argv) {
  const mbslam::CommandLineArgs args(argc, argv);
  const std::string url = args.Get("url");
  const int64_t pid = args.GetInt("pid", 0);
  const double seconds = args.GetDouble("seconds", 0.0), interval = args.GetDouble("interval", 5.0);
  const std::string problems = args.Problems();
  if (!problems.empty()) std::fprintf(stderr, "soak_monitor: %s\n", problems.c_str());
  if (!problems.empty() || pid > std::numeric_limits<int>::max()) {
    std::fprintf(stderr, "usage: soak_monitor --url URL --pid PID --seconds S [--interval S]\n");
    return 2;
  }
  if (url.empty() || pid <= 0 || seconds <= 0.0 || interval <= 0.0) {
    std::fprintf(stderr, "usage: soak_monitor --url URL --pid PID --seconds S [--interval S]\n");
    return 2;
  }
  mbslam::Status status;
  auto bus = mbslam::LcmBus::Create(url, &status);
  if (!bus) {
    std::fprintf(stderr, "soak_monitor: %s\n", status.message().c_str());
    return 1;
  }
  const mbslam::ChannelOptions ch;
  int64_t received = 0, processed = 0, dropped = 0, points = 0, keyframes = 0, observations = 0;
  int64_t occupancy = 0, occupancy_mem = 0, trajectory_poses = 0;
  int64_t heap_in_use = -1, heap_held = -1, results_kept = -1;
  bus->Subscribe(ch.perception_status, [&](const std::string&, const uint8_t* d, size_t n, int64_t) {
    mbslam::status_t m{};
    if (!mbslam::DecodeLcmMessage(d, n, &m).ok()) return;
    received = m.frames_received;
    processed = m.frames_processed;
    dropped = m.frames_dropped;
    heap_in_use = m.heap_in_use_bytes;
    heap_held = m.heap_held_bytes;
    results_kept = m.results_kept_bytes;
  });
  bus->Subscribe(ch.perception_map, [&](const std::string&, const uint8_t* d, size_t n, int64_t) {
    mbslam::map_t m{};
    if (!mbslam::DecodeLcmMessage(d, n, &m).ok()) return;
    points = m.num_points;
    keyframes = m.num_keyframes;
    observations = 0;
    for (const auto& k : m.keyframes) observations += k.num_observations;
  });
  bus->Subscribe(ch.perception_occupancy, [&](const std::string&, const uint8_t* d, size_t n, int64_t) {
    mbslam::occupancy_t m{};
    if (!mbslam::DecodeLcmMessage(d, n, &m).ok()) return;
    occupancy = m.size;
    // The service's own tree (probabilities, free space): what its memory holds. The
    // published maximum-likelihood tree is smaller and would hide growth.
    occupancy_mem = m.memory_bytes;
  });
  bus->Subscribe(ch.perception_camera_pose, [&](const std::string&, const uint8_t* d, size_t n, int64_t) {
    mbslam::camera_pose_t m{};
    if (!mbslam::DecodeLcmMessage(d, n, &m).ok()) return;
    trajectory_poses += m.tracking_state == mbslam::camera_pose_t::TRACKING_OK ||
                        m.tracking_state == mbslam::camera_pose_t::TRACKING_RELOCALIZED;
  }, 1000);
  bus->Subscribe(ch.perception_objects, [&](const std::string&, const uint8_t* d, size_t n, int64_t) {
    mbslam::objects_t m{};
    if (!mbslam::DecodeLcmMessage(d, n, &m).ok()) return;
    for (const auto& o : m.objects) trajectory_poses += o.state != mbslam::object_t::STATE_DETECTED;
  }, 1000);
  std::printf("t_s,rss_mb,frames_received,frames_processed,frames_dropped,map_points,map_keyframes,map_observations,"
              "occupancy_bytes,occupancy_mem_bytes,trajectory_poses,heap_in_use_mb,heap_held_mb,results_kept_mb\n");
  const int64_t start = mbslam::MonotonicUtime();
  int64_t next = start;
  while (true) {
    const int64_t now = mbslam::MonotonicUtime();
    if (now >= next) {
      const double rss = RssMb(static_cast<int>(pid));
      if (rss < 0.0) break;
      auto mb = [](int64_t bytes) { return bytes < 0 ? -1.0 : static_cast<double>(bytes) / (1024.0 * 1024.0); };
      std::printf("%.1f,%.2f,%lld,%lld,%lld,%lld,%lld,%lld,%lld,%lld,%lld,%.3f,%.3f,%.3f\n", mbslam::UtimeToSeconds(now - start), rss,
                  static_cast<long long>(received), static_cast<long long>(processed),
                  static_cast<long long>(dropped), static_cast<long long>(points),
                  static_cast<long long>(keyframes), static_cast<long long>(observations),
                  static_cast<long long>(occupancy), static_cast<long long>(occupancy_mem),
                  static_cast<long long>(trajectory_poses), mb(heap_in_use), mb(heap_held), mb(results_kept));
      std::fflush(stdout);
      if (now - start >= mbslam::SecondsToUtime(seconds)) break;
      next += mbslam::SecondsToUtime(interval);
    }
    bus->HandleTimeout(100);
  }
  return 0;
}
