// mbslam-eval-occupancy: an occupancy map (.bt) against the voxelised ground truth of
// a simulator sequence folder. Prints a summary and, as its last line, one JSON object.
//
//   mbslam-eval-occupancy --bt out/run/occupancy.bt --est-traj out/run/camera.tum
//       --sequence out/static [--resolution 0.1] [--max-range 20] [--align sim3|se3|none]
//       [--pixel-step 1] [--frame-step 1] [--all-frames] [--max-dt-us 20000] [--json FILE]

#include <exception>
#include <iomanip>
#include <iostream>
#include <limits>
#include <string>

#include "common/util/atomic_file.h"
#include "common/util/command_line.h"
#include "tools/eval/json.h"
#include "tools/eval/trajectory.h"
#include "tools/occupancy_eval/occupancy_eval.h"

namespace {

namespace eval = mbslam::eval;

constexpr char kUsage[] =
    "usage: mbslam-eval-occupancy --bt MAP.bt --sequence DIR [--est-traj EST.tum]\n"
    "         [--align sim3|se3|none] [--resolution M] [--max-range M] [--pixel-step N]\n"
    "         [--frame-step N] [--all-frames] [--max-dt-us US] [--json FILE]\n"
    "  --bt          the occupancy map (OctoMap binary, e.g. perception_service's occupancy.bt)\n"
    "  --sequence    simulator sequence folder (depth/, masks/, cam_trajectory.tum)\n"
    "  --est-traj    estimated world_from_cam of the run (TUM), in the map's frame;\n"
    "                needed unless --align none\n"
    "  --align       estimated frame -> ground truth by Umeyama on camera centres (default sim3)\n"
    "  --resolution  scoring voxel edge in m (default: the map's voxel edge after alignment)\n"
    "  --max-range   true voxels count for recall when seen within this range, m (default 20)\n"
    "  --pixel-step  use every N-th depth pixel in rows and columns (default 1)\n"
    "  --frame-step  use every N-th frame (default 1)\n"
    "  --all-frames  also frames outside the estimated trajectory's time span\n";

int Fail(const std::string& message) {
  std::cerr << "mbslam-eval-occupancy: " << message << "\n";
  return 1;
}

int Run(int argc, char** argv) {
  const mbslam::CommandLineArgs args(argc, argv);
  if (args.Has("help") || argc == 1) {
    std::cout << kUsage;
    return argc == 1 ? 1 : 0;
  }
  eval::OccupancyEvalOptions options;
  options.resolution_m = args.GetDouble("resolution", options.resolution_m);
  options.max_range_m = args.GetDouble("max-range", options.max_range_m);
  const int64_t pixel_step = args.GetInt("pixel-step", options.pixel_step);
  const int64_t frame_step = args.GetInt("frame-step", options.frame_step);
  const int64_t max_dt = args.GetInt("max-dt-us", options.max_time_diff_us);
  for (const auto& [name, step] : {std::pair{"--pixel-step", pixel_step}, std::pair{"--frame-step", frame_step}}) {
    if (step < 1 || step > std::numeric_limits<int>::max()) {
      return Fail(std::string(name) + " expects a whole number from 1 to " +
                  std::to_string(std::numeric_limits<int>::max()));
    }
  }
  options.pixel_step = static_cast<int>(pixel_step);
  options.frame_step = static_cast<int>(frame_step);
  options.max_time_diff_us = max_dt;
  options.all_frames = args.Has("all-frames");
  options.alignment = args.Get("align", options.alignment);
  const std::string bt = args.Get("bt");
  const std::string sequence = args.Get("sequence");
  const std::string est_path = args.Get("est-traj");
  const bool write_json = args.Has("json");
  const std::string json_path = args.Get("json");
  const std::string problems = args.Problems();
  if (!problems.empty()) {
    return Fail(problems + "\n" + kUsage);
  }
  if (bt.empty() || sequence.empty()) {
    return Fail(std::string("--bt and --sequence are required\n") + kUsage);
  }
  if (!options.Check()) {
    return Fail(mbslam::LastOptionError());
  }
  eval::Trajectory est;
  if (!est_path.empty()) {
    const mbslam::Status st = eval::ReadTumTrajectory(est_path, &est);
    if (!st.ok()) {
      return Fail(st.message());
    }
  }
  eval::OccupancyEvalResult r;
  const mbslam::Status st = eval::EvaluateOccupancy(bt, est, sequence, options, &r);
  if (!st.ok()) {
    return Fail(st.message());
  }

  const eval::OccupancyScore& s = r.score;
  std::cout << std::fixed << std::setprecision(4);
  std::cout << "occupancy map " << bt << " vs " << sequence << "\n"
            << "  alignment " << options.alignment << ": scale " << r.gt_from_est.scale << ", "
            << r.aligned_poses << " poses, camera ATE rmse " << r.ate_rmse_m << " m\n"
            << "  map voxel " << r.est_resolution << " map units = " << r.est_resolution_m
            << " m; scoring voxel " << r.resolution_m << " m; range bound " << options.max_range_m
            << " m; " << r.frames_used << " depth maps\n"
            << "  precision " << s.precision << "  (" << s.voxels_est_near << " of " << s.voxels_est
            << " occupied voxels within one voxel of the true surface)\n"
            << "  recall    " << s.recall << "  (" << s.voxels_true_found << " of " << s.voxels_true
            << " observed surface voxels within one voxel of the map; " << s.voxels_true_all
            << " at any range)\n";

  eval::Json json = eval::Json::Object();
  json.Set("occupancy_precision", s.precision)
      .Set("occupancy_recall", s.recall)
      .Set("voxels_est", s.voxels_est)
      .Set("voxels_true", s.voxels_true)
      .Set("resolution_m", r.resolution_m)
      .Set("voxels_est_near", s.voxels_est_near)
      .Set("voxels_true_found", s.voxels_true_found)
      .Set("voxels_true_all", s.voxels_true_all)
      .Set("max_range_m", options.max_range_m)
      .Set("est_resolution", r.est_resolution)
      .Set("est_resolution_m", r.est_resolution_m)
      .Set("alignment", options.alignment)
      .Set("alignment_scale", r.gt_from_est.scale)
      .Set("aligned_poses", r.aligned_poses)
      .Set("ate_rmse_m", r.ate_rmse_m)
      .Set("frames_used", r.frames_used);
  const std::string text = json.Dump();
  if (write_json) {
    const mbslam::Status written = mbslam::WriteStringAtomically(json_path, text + "\n");
    if (!written.ok()) {
      return Fail(written.message());
    }
  }
  std::cout << text << std::endl;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Run(argc, argv);
  } catch (const std::exception& e) {
    return Fail(std::string("unexpected error: ") + e.what());
  }
}
