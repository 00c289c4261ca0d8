// Crash safety of the output files: a process saving the service's outputs
// (ResultRecorder::Write, which perception_service calls on exit and on
// SNAPSHOT_REQUEST: camera_trajectory.tum, map.ply, occupancy.bt, summary.json through
// common/util/atomic_file) in a loop is killed with SIGKILL at random moments. After
// every kill each file must be a complete, parseable version: the previous one or the
// new one, never a torn mix. A control run with plain (non-atomic) writes must be
// caught by the same checks, so the checks can fail.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <dirent.h>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <thread>

#include <octomap/OcTree.h>

#include "common/testing/temp_dir.h"
#include "common/util/atomic_file.h"
#include "services/perception/pipeline/result_recorder.h"

namespace mbslam {
namespace {

constexpr double kResolution = 0.1;  // m

// Two versions of the outputs, different in size and content, so that a file from
// one and a file from the other are both valid but a mix is not.
struct Version {
  int poses = 0;
  int points = 0;
  int voxels = 0;
  std::string octree;   // writeBinary bytes
  size_t leaves = 0;    // leaf nodes of that tree
  std::unique_ptr<ResultRecorder> recorder;
};

Version MakeVersion(int g) {
  Version v;
  v.poses = 20000 + 3000 * g;
  v.points = 60000 + 10000 * g;
  v.voxels = 20000 + 5000 * g;
  octomap::OcTree tree(kResolution);
  for (int i = 0; i < v.voxels; ++i) {
    tree.updateNode(octomap::point3d(0.1f * (i % 50), 0.1f * ((i / 50) % 50), 0.1f * (i / 2500) + g), true);
  }
  std::ostringstream bt;
  tree.writeBinary(bt);
  v.octree = bt.str();
  v.leaves = tree.getNumLeafNodes();
  v.recorder = std::make_unique<ResultRecorder>();
  for (int i = 0; i < v.poses; ++i) {
    FrameResult r;
    r.utime = 1000000 + int64_t{1000} * i;
    r.camera_pose.utime = r.utime;
    r.camera_pose.tracking_state = TrackingState::kOk;
    r.camera_pose.world_from_cam.translation = Eigen::Vector3d(g, 0.001 * i, 0.0);
    if (i + 1 == v.poses) {
      MapOutput map;
      map.utime = r.utime;
      for (int k = 0; k < v.points; ++k) {
        map.point_ids.push_back(k);
        map.points.emplace_back(0.001f * k, static_cast<float>(g), 1.0f);
        map.colors.push_back({100, 100, 100});
      }
      r.map = std::move(map);
      OccupancyOutput occ;
      occ.utime = r.utime;
      occ.resolution = kResolution;
      occ.num_occupied = static_cast<int>(v.leaves);
      occ.octree_binary = v.octree;
      r.occupancy = std::move(occ);
    }
    v.recorder->OnFrameResult(r);
  }
  return v;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

// Which version (0, 1) a file is, or an error.
int CheckTum(const std::string& text, const Version* versions, std::string* error) {
  if (text.empty() || text.back() != '\n') return *error = "trajectory: no final newline", -1;
  const std::vector<std::string> lines = Lines(text);
  if (lines.size() < 2 || lines[0][0] != '#') return *error = "trajectory: no header", -1;
  int g = -1;
  for (size_t i = 1; i < lines.size(); ++i) {
    std::istringstream in(lines[i]);
    double f[8];
    for (double& x : f) in >> x;
    if (!in) return *error = "trajectory: bad line " + std::to_string(i), -1;
    if (i == 1) g = static_cast<int>(f[1]);
    if (g < 0 || g > 1 || f[1] != g) return *error = "trajectory: mixed versions", -1;
  }
  if (static_cast<int>(lines.size()) - 1 != versions[g].poses) return *error = "trajectory: truncated", -1;
  return g;
}

int CheckPly(const std::string& text, const Version* versions, std::string* error) {
  const std::vector<std::string> lines = Lines(text);
  size_t end_header = 0;
  int vertices = -1;
  for (size_t i = 0; i < lines.size() && !end_header; ++i) {
    if (lines[i].rfind("element vertex ", 0) == 0) vertices = std::stoi(lines[i].substr(15));
    if (lines[i] == "end_header") end_header = i;
  }
  if (lines.empty() || lines[0] != "ply" || !end_header || vertices < 0) return *error = "map: bad header", -1;
  if (lines.size() - end_header - 1 != static_cast<size_t>(vertices)) return *error = "map: truncated", -1;
  int g = -1;
  for (size_t i = end_header + 1; i < lines.size(); ++i) {
    std::istringstream in(lines[i]);
    double x, y, z;
    int r, gr, b;
    in >> x >> y >> z >> r >> gr >> b;
    if (!in) return *error = "map: bad vertex", -1;
    if (g < 0) g = static_cast<int>(y);
    if (y != g) return *error = "map: mixed versions", -1;
  }
  if (g < 0 || g > 1 || versions[g].points != vertices) return *error = "map: wrong size", -1;
  return g;
}

int CheckOctree(const std::string& bytes, const Version* versions, std::string* error) {
  octomap::OcTree tree(kResolution);
  std::istringstream in(bytes);
  if (!tree.readBinary(in)) return *error = "occupancy.bt: readBinary failed", -1;
  std::ostringstream again;
  tree.writeBinary(again);
  for (int g = 0; g < 2; ++g) {
    if (again.str() == versions[g].octree && bytes == versions[g].octree && tree.getNumLeafNodes() == versions[g].leaves) {
      return g;
    }
  }
  return *error = "occupancy.bt: not a complete version", -1;
}

int CheckSummary(const std::string& text, const Version* versions, std::string* error) {
  if (text.size() < 3 || text.substr(text.size() - 2) != "}\n") return *error = "summary: truncated", -1;
  for (int g = 0; g < 2; ++g) {
    if (text.find("\"generation\": " + std::to_string(g)) != std::string::npos &&
        text.find("\"frames\": " + std::to_string(versions[g].poses) + ",") != std::string::npos &&
        text.find("\"map_points\": " + std::to_string(versions[g].points) + ",") != std::string::npos) {
      return g;
    }
  }
  return *error = "summary: inconsistent", -1;
}

// All four files complete; "" if so, else what is wrong.
std::string CheckOutputs(const std::string& dir, const Version* versions) {
  std::string error, text;
  const std::pair<const char*, int (*)(const std::string&, const Version*, std::string*)> files[] = {
      {"camera_trajectory.tum", CheckTum}, {"map.ply", CheckPly}, {"occupancy.bt", CheckOctree},
      {"summary.json", CheckSummary}};
  for (const auto& [name, check] : files) {
    const Status read = ReadFileToString(dir + "/" + name, &text);
    if (!read.ok()) return read.message();
    if (check(text, versions, &error) < 0) return error;
  }
  return "";
}

// Temporary files in `dir` (of the writer `pid` only, if given).
int CountTempFiles(const std::string& dir, pid_t pid = 0) {
  const std::string tag = pid ? ".tmp." + std::to_string(pid) : ".tmp.";
  int n = 0;
  if (DIR* d = opendir(dir.c_str())) {
    while (const dirent* e = readdir(d)) {
      const std::string name = e->d_name;
      const size_t at = name.find(tag);
      n += at != std::string::npos && (!pid || at + tag.size() == name.size());
    }
    closedir(d);
  }
  return n;
}

// The control: the same bytes written in place, as a careless writer would.
void WriteInPlace(const std::string& dir, const std::vector<std::pair<std::string, std::string>>& files) {
  for (const auto& [name, bytes] : files) {
    std::ofstream out(dir + "/" + name, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
}

struct KillLoopResult {
  int rounds = 0;
  int torn = 0;              // rounds after which some file was not a complete version
  int killed_mid_save = 0;   // rounds that left a temporary file (the kill hit a save)
  std::string first_error;
};

// Forks a writer `rounds` times and kills it: in even rounds at a random moment of
// its save loop, in odd rounds (atomic saves) as soon as one of its saves has a
// temporary file.
KillLoopResult KillLoop(const std::string& dir, const Version* versions, bool atomic, int rounds, uint32_t seed) {
  std::vector<std::pair<std::string, std::string>> plain[2];
  if (!atomic) {
    for (int g = 0; g < 2; ++g) {
      const std::string stage = dir + "/stage" + std::to_string(g);
      EXPECT_TRUE(versions[g].recorder->Write(stage, "\"generation\": " + std::to_string(g)).ok());
      for (const char* name : {"camera_trajectory.tum", "map.ply", "occupancy.bt", "summary.json"}) {
        std::string bytes;
        EXPECT_TRUE(ReadFileToString(stage + "/" + name, &bytes).ok());
        plain[g].emplace_back(name, bytes);
      }
    }
  }
  const std::string out = dir + "/out";
  // A first complete save, so that "the previous file" exists from the first kill on.
  EXPECT_TRUE(versions[0].recorder->Write(out, "\"generation\": 0").ok());
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> delay_us(2000, 40000);
  KillLoopResult result;
  for (int round = 0; round < rounds; ++round) {
    const pid_t child = fork();
    if (child == 0) {
      for (int k = round;; ++k) {
        const int g = k % 2;
        if (atomic) {
          versions[g].recorder->Write(out, "\"generation\": " + std::to_string(g));
        } else {
          WriteInPlace(out, plain[g]);
        }
      }
    }
    if (!atomic || round % 2 == 0) {
      // At a random moment of the loop: mostly between saves, as a save's temporary
      // file exists for a small share of it.
      std::this_thread::sleep_for(std::chrono::microseconds(delay_us(rng)));
    } else {
      // Aimed: as soon as the writer has a temporary file open (or after 2 s).
      const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(2);
      while (CountTempFiles(out, child) == 0 && std::chrono::steady_clock::now() < give_up) {
      }
    }
    kill(child, SIGKILL);
    int status = 0;
    waitpid(child, &status, 0);
    ++result.rounds;
    // A temporary file of this writer: the kill hit it inside a save (the next
    // writer's first save removes it).
    if (CountTempFiles(out, child) > 0) ++result.killed_mid_save;
    const std::string error = CheckOutputs(out, versions);
    if (!error.empty()) {
      ++result.torn;
      if (result.first_error.empty()) result.first_error = error;
    }
  }
  return result;
}

class OutputCrashSafety : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    versions_ = new Version[2];
    versions_[0] = MakeVersion(0);
    versions_[1] = MakeVersion(1);
  }
  static void TearDownTestSuite() { delete[] versions_; }
  static std::string TempDir() { return testing_util::MakeTestTempDir("crash"); }
  static Version* versions_;
};
Version* OutputCrashSafety::versions_ = nullptr;

TEST_F(OutputCrashSafety, KillDuringAtomicSavesAlwaysLeavesCompleteFiles) {
  const std::string dir = TempDir();
  const KillLoopResult r = KillLoop(dir, versions_, /*atomic=*/true, 80, 11);
  std::printf("atomic saves: %d kills, %d during a save, %d left a torn file\n", r.rounds, r.killed_mid_save, r.torn);
  EXPECT_EQ(r.torn, 0) << r.first_error;
  EXPECT_GT(r.killed_mid_save, 0) << "no kill landed inside a save: the test did not test anything";
  // The temporary files of the killed writers are cleaned up by the next save.
  ASSERT_TRUE(versions_[1].recorder->Write(dir + "/out", "\"generation\": 1").ok());
  EXPECT_EQ(CountTempFiles(dir + "/out"), 0);
  EXPECT_EQ(CheckOutputs(dir + "/out", versions_), "");
}

TEST_F(OutputCrashSafety, ControlInPlaceWritesAreCaught) {
  const std::string dir = TempDir();
  const KillLoopResult r = KillLoop(dir, versions_, /*atomic=*/false, 40, 12);
  std::printf("in-place writes: %d kills, %d left a torn file (first: %s)\n", r.rounds, r.torn, r.first_error.c_str());
  EXPECT_GT(r.torn, 0) << "the checks did not notice torn files";
}

}  // namespace
}  // namespace mbslam
