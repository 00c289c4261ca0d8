#ifndef MBSLAM_TEST_INTEGRATION_FAULT_TEST_UTIL_H_
#define MBSLAM_TEST_INTEGRATION_FAULT_TEST_UTIL_H_

// Shared by the fault-injection tests: the input sequence, decoding the output log,
// the recovery figure and the one-line JSON report that scripts/eval.d/faults.sh
// collects ("FAULT_JSON {...}" on stdout).

#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "common/lcm/channels.h"
#include "common/lcm/lcm_log.h"
#include "common/lcm/wire_check.h"
#include "common/testing/temp_dir.h"
#include "mbslam/camera_pose_t.hpp"
#include "mbslam/map_t.hpp"
#include "mbslam/objects_t.hpp"
#include "mbslam/occupancy_t.hpp"
#include "mbslam/status_t.hpp"
#include "mbslam/tracks_t.hpp"
#include "test/drivers/process_util.h"

namespace mbslam {
namespace fault_test {

// The simulated input: scenario `static`, 320x240 at 15 Hz, 240 frames (16 s), made
// by the CTest fixture (MBSLAM_FAULT_SEQUENCE) or, when run alone, here.
inline constexpr int kSequenceFrames = 240;
inline constexpr double kSequenceFps = 15.0;

inline bool FileExists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

// Returns the sequence folder (with sequence.lcmlog, images/, timestamps.txt), or ""
// with `error` set.
inline std::string EnsureSequence(std::string* error) {
  const char* env = std::getenv("MBSLAM_FAULT_SEQUENCE");
  std::string dir = env && *env ? env : "/tmp/mbslam_fault_sequence_" + std::to_string(::getuid());
  if (FileExists(dir + "/sequence.lcmlog") && FileExists(dir + "/timestamps.txt")) return dir;
  const auto r = testing_util::RunProcess(
      {testing_util::BinPath("mbslam-sim"), "--quiet", "--scenario", "static", "--size", "320x240", "--fps",
       std::to_string(static_cast<int>(kSequenceFps)), "--frames", std::to_string(kSequenceFrames),
       "--depth", "png", "--out", dir},
      300.0);
  if (r.exit_code != 0 || !FileExists(dir + "/sequence.lcmlog")) {
    *error = "mbslam-sim failed (exit " + std::to_string(r.exit_code) + "): " + r.err;
    return "";
  }
  return dir;
}

// Every event of an output log decodes as the type of its channel.
struct OutputLogCheck {
  int events = 0;
  int poses = 0;
  std::map<std::string, int> per_channel;
  std::string error;  // empty = all decoded
};

inline OutputLogCheck CheckOutputLog(const std::string& path, const ChannelOptions& ch = ChannelOptions()) {
  OutputLogCheck out;
  std::vector<LcmLogEvent> events;
  const Status read = ReadLcmLog(path, &events);
  if (!read.ok()) {
    out.error = read.message();
    return out;
  }
  for (const LcmLogEvent& e : events) {
    ++out.events;
    ++out.per_channel[e.channel];
    Status s = Status::Error("unexpected channel " + e.channel);
    const uint8_t* d = e.data.data();
    const size_t n = e.data.size();
    if (e.channel == ch.perception_camera_pose) {
      mbslam::camera_pose_t m{};
      s = DecodeLcmMessage(d, n, &m);
      ++out.poses;
    } else if (e.channel == ch.perception_objects) {
      mbslam::objects_t m{};
      s = DecodeLcmMessage(d, n, &m);
    } else if (e.channel == ch.perception_map) {
      mbslam::map_t m{};
      s = DecodeLcmMessage(d, n, &m);
    } else if (e.channel == ch.perception_occupancy) {
      mbslam::occupancy_t m{};
      s = DecodeLcmMessage(d, n, &m);
    } else if (e.channel == ch.perception_tracks) {
      mbslam::tracks_t m{};
      s = DecodeLcmMessage(d, n, &m);
    } else if (e.channel == ch.perception_status) {
      mbslam::status_t m{};
      s = DecodeLcmMessage(d, n, &m);
    }
    if (!s.ok() && out.error.empty()) {
      out.error = "event " + std::to_string(out.events) + " on " + e.channel + ": " + s.message();
    }
  }
  return out;
}

inline bool Tracked(int8_t state) {
  return state == mbslam::camera_pose_t::TRACKING_OK || state == mbslam::camera_pose_t::TRACKING_RELOCALIZED;
}

// Frames processed from `first` (an index into `poses`) until tracking is back for
// `sustain` frames in a row (or to the end of the run); -1 if it never is.
inline int FramesToRecover(const std::vector<mbslam::camera_pose_t>& poses, size_t first, int sustain = 5) {
  for (size_t k = first; k < poses.size(); ++k) {
    size_t run = 0;
    while (k + run < poses.size() && run < static_cast<size_t>(sustain) && Tracked(poses[k + run].tracking_state)) {
      ++run;
    }
    if (run == static_cast<size_t>(sustain) || (run > 0 && k + run == poses.size())) {
      return static_cast<int>(k - first);
    }
  }
  return -1;
}

// Index of the first pose with frame_seq >= seq (poses.size() if none).
inline size_t FirstPoseAtOrAfter(const std::vector<mbslam::camera_pose_t>& poses, int64_t seq) {
  for (size_t k = 0; k < poses.size(); ++k) {
    if (poses[k].frame_seq >= seq) return k;
  }
  return poses.size();
}

// Share of tracked poses with frame_seq in [from, to).
inline double TrackedFraction(const std::vector<mbslam::camera_pose_t>& poses, int64_t from, int64_t to) {
  int n = 0, tracked = 0;
  for (const auto& p : poses) {
    if (p.frame_seq < from || p.frame_seq >= to) continue;
    ++n;
    tracked += Tracked(p.tracking_state);
  }
  return n ? static_cast<double>(tracked) / n : 0.0;
}

inline std::map<std::string, int64_t> Counters(const mbslam::status_t& s) {
  std::map<std::string, int64_t> out;
  for (const auto& c : s.counters) out[c.name] = c.value;
  return out;
}

// One line for scripts/eval.d/faults.sh.
struct FaultReport {
  std::string name;
  bool survived = false;
  int frames_to_recover = -1;
  int recovery_bound = 0;
  std::map<std::string, int64_t> status_counter;  // the counters that report this fault
  std::vector<std::string> states_seen;           // status states during the run
  std::string note;
};

inline std::string JsonEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    out += c;
  }
  return out;
}

inline void PrintFaultReport(const FaultReport& r) {
  std::ostringstream o;
  o << "{\"name\": \"" << r.name << "\", \"survived\": " << (r.survived ? "true" : "false")
    << ", \"frames_to_recover\": " << r.frames_to_recover << ", \"recovery_bound\": " << r.recovery_bound
    << ", \"status_counter\": {";
  bool first = true;
  for (const auto& [k, v] : r.status_counter) {
    o << (first ? "" : ", ") << "\"" << k << "\": " << v;
    first = false;
  }
  o << "}, \"states_seen\": [";
  first = true;
  for (const auto& s : r.states_seen) {
    o << (first ? "" : ", ") << "\"" << s << "\"";
    first = false;
  }
  o << "], \"note\": \"" << JsonEscape(r.note) << "\"}";
  std::printf("FAULT_JSON %s\n", o.str().c_str());
  std::fflush(stdout);
}

inline const char* StateName(int8_t state) {
  switch (state) {
    case mbslam::status_t::STATE_STARTING: return "starting";
    case mbslam::status_t::STATE_RUNNING: return "running";
    case mbslam::status_t::STATE_DEGRADED: return "degraded";
    case mbslam::status_t::STATE_STALLED: return "stalled";
    case mbslam::status_t::STATE_STOPPING: return "stopping";
  }
  return "unknown";
}

}  // namespace fault_test
}  // namespace mbslam

#endif  // MBSLAM_TEST_INTEGRATION_FAULT_TEST_UTIL_H_
