// Known answers for the occupancy evaluation: a map built from the true geometry itself
// scores ~1, a shifted one scores low, and moving bodies never count as static surface.

#include "tools/occupancy_eval/occupancy_eval.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "common/util/atomic_file.h"
#include "services/perception/geometry/camera.h"
#include "services/perception/occupancy/occupancy_map.h"
#include "tools/eval/json.h"
#include "tools/eval/trajectory.h"
#include "test/tools/run_command.h"

namespace mbslam {
namespace eval {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 160;
constexpr int kHeight = 120;
constexpr int kFrames = 10;
constexpr double kWallX = 6.0;       // a wall x = 6 m ...
constexpr double kMoverDepth = 2.5;  // ... and a moving body 2.5 m in front of the camera
constexpr int kMoverId = 3;

CameraIntrinsics Intrinsics() {
  CameraIntrinsics K;
  K.name = "test";
  K.width = kWidth;
  K.height = kHeight;
  K.fx = K.fy = 100.0;
  K.cx = 79.5;
  K.cy = 59.5;
  return K;
}

// Camera k looks along world x (camera z), image right = world -y, image down = world
// -z, about 1.5 m above the ground z = 0, moving sideways and forward (not on a line, so
// that the trajectory fixes the alignment).
Rigid3d TruePose(int k) {
  Eigen::Matrix3d world_from_cam_rotation;
  world_from_cam_rotation.col(0) = Eigen::Vector3d(0, -1, 0);
  world_from_cam_rotation.col(1) = Eigen::Vector3d(0, 0, -1);
  world_from_cam_rotation.col(2) = Eigen::Vector3d(1, 0, 0);
  return Rigid3d(world_from_cam_rotation,
                 Eigen::Vector3d(0.3 * k, -1.0 + 0.2 * k + 0.15 * (k % 3), 1.5 + 0.05 * (k % 2)));
}

bool IsMoverPixel(int u, int v) { return u >= 60 && u < 90 && v >= 30 && v < 60; }

// Depth along the optical axis of the static world (ground or wall) at a pixel.
double StaticDepth(const Rigid3d& world_from_cam, int u, int v) {
  const CameraIntrinsics K = Intrinsics();
  const Eigen::Vector3d ray((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);  // z = 1
  const Eigen::Vector3d d = world_from_cam.rotation * ray;
  const Eigen::Vector3d& c = world_from_cam.translation;
  double t = (kWallX - c.x()) / d.x();
  if (d.z() < 0.0) {
    t = std::min(t, c.z() / -d.z());
  }
  return t;
}

// Writes a sequence folder: calibration, timestamps, true trajectory, EXR depth, masks.
void WriteSequence(const fs::path& dir) {
  fs::create_directories(dir / "depth");
  fs::create_directories(dir / "masks");
  ASSERT_TRUE(WriteStringAtomically((dir / "calibration.yaml").string(),
                                    CameraIntrinsicsToYaml(Intrinsics()))
                  .ok());
  std::string stamps;
  Trajectory truth;
  for (int k = 0; k < kFrames; ++k) {
    const int64_t utime = 1600000000000000 + int64_t{33333} * k;
    stamps += std::to_string(k) + " " + std::to_string(utime) + "\n";
    truth.push_back({utime, TruePose(k)});
    cv::Mat depth(kHeight, kWidth, CV_32F), mask(kHeight, kWidth, CV_16U, cv::Scalar(0));
    for (int v = 0; v < kHeight; ++v) {
      for (int u = 0; u < kWidth; ++u) {
        depth.at<float>(v, u) = static_cast<float>(StaticDepth(TruePose(k), u, v));
        if (IsMoverPixel(u, v)) {
          depth.at<float>(v, u) = static_cast<float>(kMoverDepth);
          mask.at<uint16_t>(v, u) = kMoverId;
        }
      }
    }
    char name[32];
    std::snprintf(name, sizeof(name), "%06d", k);
    ASSERT_TRUE(cv::imwrite((dir / "depth" / (std::string(name) + ".exr")).string(), depth));
    ASSERT_TRUE(cv::imwrite((dir / "masks" / (std::string(name) + ".png")).string(), mask));
  }
  ASSERT_TRUE(WriteStringAtomically((dir / "timestamps.txt").string(), stamps).ok());
  ASSERT_TRUE(WriteTumTrajectory((dir / "cam_trajectory.tum").string(), truth).ok());
}

// A SLAM-like frame: est_from_gt = scale 0.5, a rotation, a translation.
Sim3d EstFromGt() {
  Sim3d s;
  s.scale = 0.5;
  s.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  s.translation = Eigen::Vector3d(1.0, -2.0, 0.5);
  return s;
}

struct MapRecipe {
  Eigen::Vector3d shift_m = Eigen::Vector3d::Zero();  // moves the geometry (gt frame)
  bool burn_in_mover = false;                         // also insert the moving body
  double resolution_m = 0.1;                          // voxel edge of the map (m)
  int pixel_step = 2;  // rays to every this many pixels (at 6 m a pixel is 6 cm)
};

// Builds a .bt in the estimated frame from the true depth, as a perfect SLAM would, and
// writes the estimated trajectory.
void BuildMap(const MapRecipe& recipe, const std::string& bt, const std::string& est_tum) {
  const Sim3d est_from_gt = EstFromGt();
  OccupancyMapOptions options;
  options.resolution_m = recipe.resolution_m * est_from_gt.scale;
  options.max_range_m = 20.0 * est_from_gt.scale;
  OccupancyMap map(options, OccupancyMap::Units::kMetres);
  const CameraIntrinsics K = Intrinsics();
  Trajectory est;
  for (int k = 0; k < kFrames; ++k) {
    const Rigid3d world_from_cam = TruePose(k);
    std::vector<Eigen::Vector3d> points;
    for (int v = 0; v < kHeight; v += recipe.pixel_step) {
      for (int u = 0; u < kWidth; u += recipe.pixel_step) {
        const bool mover = IsMoverPixel(u, v);
        if (mover && !recipe.burn_in_mover) {
          continue;
        }
        const double z = mover ? kMoverDepth : StaticDepth(world_from_cam, u, v);
        const Eigen::Vector3d p_cam((u - K.cx) / K.fx * z, (v - K.cy) / K.fy * z, z);
        points.push_back(est_from_gt * (world_from_cam * p_cam + recipe.shift_m));
      }
    }
    const Eigen::Vector3d camera = est_from_gt * (world_from_cam.translation + recipe.shift_m);
    map.InsertRays(camera, points);
    if (recipe.burn_in_mover) {
      // The body seen again and again, as a SLAM that took it for static would: enough
      // hits that the free space of later frames does not clear it.
      std::vector<Eigen::Vector3d> body;
      for (int v = 0; v < kHeight; v += recipe.pixel_step) {
        for (int u = 0; u < kWidth; u += recipe.pixel_step) {
          if (!IsMoverPixel(u, v)) {
            continue;
          }
          const Eigen::Vector3d p_cam((u - K.cx) / K.fx * kMoverDepth,
                                      (v - K.cy) / K.fy * kMoverDepth, kMoverDepth);
          body.push_back(est_from_gt * (world_from_cam * p_cam + recipe.shift_m));
        }
      }
      for (int repeat = 0; repeat < 4; ++repeat) {
        map.InsertRays(camera, body);
      }
    }
    est.push_back({1600000000000000 + int64_t{33333} * k, est_from_gt * world_from_cam});
  }
  ASSERT_TRUE(map.SaveBt(bt).ok());
  ASSERT_TRUE(WriteTumTrajectory(est_tum, est).ok());
}

class OccupancyEval : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ =
        new fs::path(fs::temp_directory_path() / ("mbslam_occ_eval_" + std::to_string(::getpid())));
    fs::create_directories(*dir_);
    WriteSequence(*dir_ / "seq");
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    dir_ = nullptr;
  }
  static std::string Path(const std::string& name) { return (*dir_ / name).string(); }

  static OccupancyEvalResult Evaluate(
      const MapRecipe& recipe, const std::string& name,
      const OccupancyEvalOptions& options = OccupancyEvalOptions()) {
    if (!fs::exists(Path(name + ".bt"))) {
      BuildMap(recipe, Path(name + ".bt"), Path(name + ".tum"));
    }
    Trajectory est;
    EXPECT_TRUE(ReadTumTrajectory(Path(name + ".tum"), &est).ok());
    OccupancyEvalResult result;
    const Status st = EvaluateOccupancy(Path(name + ".bt"), est, Path("seq"), options, &result);
    EXPECT_TRUE(st.ok()) << st.message();
    return result;
  }

  static fs::path* dir_;
};

fs::path* OccupancyEval::dir_ = nullptr;

TEST_F(OccupancyEval, MapOfTheTrueGeometryScoresOne) {
  const OccupancyEvalResult r = Evaluate(MapRecipe(), "truth");
  EXPECT_NEAR(r.gt_from_est.scale, 2.0, 1e-6);
  EXPECT_LT(r.ate_rmse_m, 1e-6);
  EXPECT_EQ(r.aligned_poses, kFrames);
  EXPECT_EQ(r.frames_used, kFrames);
  EXPECT_NEAR(r.est_resolution, 0.05, 1e-9);
  EXPECT_NEAR(r.est_resolution_m, 0.1, 1e-6);
  EXPECT_NEAR(r.resolution_m, 0.1, 1e-6);  // the map's own voxel edge by default
  EXPECT_GT(r.score.voxels_true, 2000);
  EXPECT_GT(r.score.voxels_est, 2000);
  EXPECT_GE(r.score.precision, 0.99);
  EXPECT_GE(r.score.recall, 0.97);
  std::printf("true geometry: precision %.4f recall %.4f (%lld est, %lld true voxels)\n",
              r.score.precision, r.score.recall, static_cast<long long>(r.score.voxels_est),
              static_cast<long long>(r.score.voxels_true));
}

TEST_F(OccupancyEval, ShiftedMapScoresLow) {
  MapRecipe shifted;
  shifted.shift_m = Eigen::Vector3d(0.5, 0.0, 0.5);  // 5 voxels off both surfaces
  const OccupancyEvalResult r = Evaluate(shifted, "shifted");
  EXPECT_LT(r.score.precision, 0.2);
  EXPECT_LT(r.score.recall, 0.2);
  std::printf("shifted 0.5 m: precision %.4f recall %.4f\n", r.score.precision, r.score.recall);
}

TEST_F(OccupancyEval, MovingBodyIsNotStaticSurface) {
  const OccupancyEvalResult clean = Evaluate(MapRecipe(), "truth");
  MapRecipe burnt;
  burnt.burn_in_mover = true;
  const OccupancyEvalResult r = Evaluate(burnt, "burnt");
  EXPECT_LT(r.score.precision, clean.score.precision - 0.02);
  EXPECT_GT(r.score.voxels_est, clean.score.voxels_est);
  std::printf("moving body burnt in: precision %.4f (clean %.4f)\n", r.score.precision,
              clean.score.precision);
}

TEST_F(OccupancyEval, RangeBoundAndScoringResolution) {
  OccupancyEvalOptions near;
  near.max_range_m = 4.0;
  const OccupancyEvalResult r4 = Evaluate(MapRecipe(), "truth", near);
  const OccupancyEvalResult r20 = Evaluate(MapRecipe(), "truth");
  EXPECT_LT(r4.score.voxels_true, r20.score.voxels_true);
  EXPECT_EQ(r4.score.voxels_true_all, r20.score.voxels_true_all);
  // A coarser scoring grid than the map: the map's voxels are sampled into it.
  OccupancyEvalOptions coarse;
  coarse.resolution_m = 0.25;
  const OccupancyEvalResult rc = Evaluate(MapRecipe(), "truth", coarse);
  EXPECT_NEAR(rc.resolution_m, 0.25, 1e-12);
  EXPECT_GE(rc.score.precision, 0.99);
  EXPECT_GE(rc.score.recall, 0.97);
  // A map twice as coarse as the scoring grid still covers the surface.
  MapRecipe coarse_map;
  coarse_map.resolution_m = 0.2;
  OccupancyEvalOptions fine;
  fine.resolution_m = 0.1;
  const OccupancyEvalResult rf = Evaluate(coarse_map, "coarse_map", fine);
  EXPECT_NEAR(rf.est_resolution_m, 0.2, 1e-6);
  EXPECT_GE(rf.score.precision, 0.95);
  EXPECT_GE(rf.score.recall, 0.95);
}

TEST_F(OccupancyEval, Errors) {
  OccupancyEvalResult r;
  OccupancyEvalOptions options;
  Evaluate(MapRecipe(), "truth");
  const std::string bt = Path("truth.bt");
  // Sim(3) alignment without a trajectory.
  EXPECT_FALSE(EvaluateOccupancy(bt, Trajectory(), Path("seq"), options, &r).ok());
  // Not an octree.
  ASSERT_TRUE(WriteStringAtomically(Path("bad.bt"), "hello").ok());
  Trajectory est;
  ASSERT_TRUE(ReadTumTrajectory(Path("truth.tum"), &est).ok());
  EXPECT_FALSE(EvaluateOccupancy(Path("bad.bt"), est, Path("seq"), options, &r).ok());
  EXPECT_FALSE(EvaluateOccupancy(Path("missing.bt"), est, Path("seq"), options, &r).ok());
  options.pixel_step = 0;
  EXPECT_FALSE(EvaluateOccupancy(bt, est, Path("seq"), options, &r).ok());
  // A trajectory outside the sequence's time span.
  options = OccupancyEvalOptions();
  Trajectory late = est;
  for (TimedPose& p : late) {
    p.utime += 1000000000;
  }
  EXPECT_FALSE(EvaluateOccupancy(bt, late, Path("seq"), options, &r).ok());
}

TEST(VoxelGrid, NeighbourhoodAndScore) {
  VoxelGrid grid(0.1);
  EXPECT_TRUE(grid.Insert(Eigen::Vector3d(0.05, 0.05, 0.05)));
  EXPECT_FALSE(grid.Insert(Eigen::Vector3d(NAN, 0, 0)));
  EXPECT_FALSE(grid.Insert(Eigen::Vector3d(1e9, 0, 0)));
  EXPECT_TRUE(grid.Contains(Eigen::Vector3d(0.01, 0.09, 0.02)));
  EXPECT_FALSE(grid.Contains(Eigen::Vector3d(0.15, 0.05, 0.05)));
  EXPECT_TRUE(grid.ContainsNear(Eigen::Vector3d(0.15, -0.05, 0.15)));
  EXPECT_FALSE(grid.ContainsNear(Eigen::Vector3d(0.25, 0.05, 0.05)));
  grid.Insert(Eigen::Vector3d(-0.05, -0.05, -0.05));
  ASSERT_EQ(grid.Centers().size(), 2u);

  // A plane of truth; the same voxels score 1, three voxels off score 0.
  TrueSurface truth;
  truth.all = VoxelGrid(0.1);
  truth.observed = VoxelGrid(0.1);
  std::vector<Eigen::Vector3d> same, off;
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j) {
      const Eigen::Vector3d c(0.1 * i + 0.05, 0.1 * j + 0.05, 0.05);
      truth.all.Insert(c);
      truth.observed.Insert(c);
      same.push_back(c);
      off.push_back(c + Eigen::Vector3d(0, 0, 0.3));
    }
  }
  const OccupancyScore s1 = ScoreOccupancy(same, 0.1, Eigen::Quaterniond::Identity(), truth);
  EXPECT_DOUBLE_EQ(s1.precision, 1.0);
  EXPECT_DOUBLE_EQ(s1.recall, 1.0);
  EXPECT_EQ(s1.voxels_est, 400);
  EXPECT_EQ(s1.voxels_true, 400);
  const OccupancyScore s2 = ScoreOccupancy(off, 0.1, Eigen::Quaterniond::Identity(), truth);
  EXPECT_DOUBLE_EQ(s2.precision, 0.0);
  EXPECT_DOUBLE_EQ(s2.recall, 0.0);
  // Half the plane: precision 1, recall about half (one voxel of tolerance).
  const std::vector<Eigen::Vector3d> half(same.begin(), same.begin() + 200);
  const OccupancyScore s3 = ScoreOccupancy(half, 0.1, Eigen::Quaterniond::Identity(), truth);
  EXPECT_DOUBLE_EQ(s3.precision, 1.0);
  EXPECT_NEAR(s3.recall, 220.0 / 400.0, 1e-12);
  // Nothing estimated.
  const OccupancyScore s4 = ScoreOccupancy({}, 0.1, Eigen::Quaterniond::Identity(), truth);
  EXPECT_EQ(s4.voxels_est, 0);
  EXPECT_DOUBLE_EQ(s4.precision, 0.0);
  EXPECT_DOUBLE_EQ(s4.recall, 0.0);
}

// ---------------------------------------------------------------- the executable
std::string Bin() { return testing_util::ToolPath("mbslam-eval-occupancy"); }

int RunCli(const std::string& args, Json* json) {
  std::string out;
  const int status = testing_util::RunCommand(Bin() + " " + args + " 2>/dev/null", &out);
  if (json && !Json::Parse(testing_util::LastLine(out), json)) {
    *json = Json();
  }
  return status;
}

TEST_F(OccupancyEval, CommandLinePrintsTheJsonKeys) {
  if (!fs::exists(Bin())) {
    GTEST_SKIP() << Bin() << " not built";
  }
  Evaluate(MapRecipe(), "truth");
  Json json;
  ASSERT_EQ(RunCli("--bt " + Path("truth.bt") + " --est-traj " + Path("truth.tum") +
                       " --sequence " + Path("seq") + " --json " + Path("cli.json"),
                   &json),
            0);
  for (const char* key :
       {"occupancy_precision", "occupancy_recall", "voxels_est", "voxels_true", "resolution_m"}) {
    ASSERT_NE(json.Find(key), nullptr) << key;
  }
  EXPECT_GE(json.Find("occupancy_precision")->AsDouble(), 0.99);
  EXPECT_GE(json.Find("occupancy_recall")->AsDouble(), 0.97);
  EXPECT_NEAR(json.Find("resolution_m")->AsDouble(), 0.1, 1e-6);
  std::string written;
  ASSERT_TRUE(ReadFileToString(Path("cli.json"), &written).ok());
  EXPECT_EQ(written, json.Dump() + "\n");

  EXPECT_NE(RunCli("--sequence " + Path("seq"), nullptr), 0);  // no --bt
  EXPECT_NE(RunCli("--bt " + Path("truth.bt") + " --sequence " + Path("seq"), nullptr),
            0);  // no traj
  EXPECT_NE(
      RunCli("--bt " + Path("truth.bt") + " --sequence " + Path("seq") + " --bogus 1", nullptr), 0);
  // Malformed or out-of-range numbers are refused before any work.
  const std::string base = "--bt " + Path("truth.bt") + " --est-traj " + Path("truth.tum") + " --sequence " + Path("seq");
  EXPECT_EQ(RunCli(base + " --pixel-step 2x", nullptr), 1);
  EXPECT_EQ(RunCli(base + " --frame-step 1.5", nullptr), 1);
  EXPECT_EQ(RunCli(base + " --pixel-step 4294967297", nullptr), 1);  // beyond an int
  EXPECT_EQ(RunCli(base + " --max-range inf", nullptr), 1);
  EXPECT_EQ(
      RunCli("--bt " + Path("truth.bt") + " --sequence " + Path("seq") + " --align none", &json),
      0);  // the map in its own frame: nothing lines up
  EXPECT_LT(json.Find("occupancy_precision")->AsDouble(), 0.2);
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
