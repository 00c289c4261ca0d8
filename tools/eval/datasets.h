#ifndef MBSLAM_TOOLS_EVAL_DATASETS_H_
#define MBSLAM_TOOLS_EVAL_DATASETS_H_

// Readers for the evaluation data sets in ../shared/data (see its README.md) and for
// the simulator's sequence folders. Data is read in place, never copied.
//
// Data root: $MBSLAM_DATA if set, else <source root>/../shared/data, where the source
// root is $MBSLAM_SOURCE_DIR if set, else the current directory.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "common/util/status.h"
#include "services/perception/geometry/camera.h"
#include "tools/eval/object_metrics.h"
#include "tools/eval/segmentation_metrics.h"
#include "tools/eval/trajectory.h"

namespace mbslam {
namespace eval {

std::string DataRoot();
// <DataRoot()>/<name> if that directory exists, else "".
std::string DataSetPath(const std::string& name);

// ---------------------------------------------------------------- feature tracks
// The *.tracks.txt format (Hopkins 155 export): line 1 "P F width height", line 2 the P
// ground-truth labels, then P lines "x1 y1 ... xF yF" (px; "nan nan" = not visible).
struct TrackSet {
  std::string name;
  int width = 0;                                     // px
  int height = 0;                                    // px
  std::vector<int> labels;                           // per point: true motion group
  std::vector<std::vector<Eigen::Vector2d>> tracks;  // [point][frame], NaN = not visible

  int num_points() const { return static_cast<int>(tracks.size()); }
  int num_frames() const { return tracks.empty() ? 0 : static_cast<int>(tracks.front().size()); }
  int NumGroups() const;
};
Status ParseTracks(const std::string& text, TrackSet* set);
Status ReadTracksFile(const std::string& path,
                      TrackSet* set);  // name = file name without .tracks.txt
Status WriteTracksFile(const std::string& path, const TrackSet& set);
// Every *.tracks.txt in a folder, sorted by name.
Status ReadTracksFolder(const std::string& dir, std::vector<TrackSet>* sets);

// A list of integer labels, whitespace separated (e.g. one predicted label per track).
Status ReadLabelFile(const std::string& path, std::vector<int>* labels);
Status WriteLabelFile(const std::string& path, const std::vector<int>& labels);

// ---------------------------------------------------------------- DAVIS 2016
struct DavisSequence {
  std::string name;
  std::vector<std::string> images;  // JPEGImages/<name>/*.jpg, sorted
  std::vector<std::string> masks;   // Annotations/<name>/*.png, same frames
};
Status ReadDavis(const std::string& root, std::vector<DavisSequence>* sequences);
// A mask image as CV_8U with 255 inside (any non-zero pixel) and 0 outside.
Status LoadBinaryMask(const std::string& path, cv::Mat* mask);

// ---------------------------------------------------------------- CamVid
struct CamVidFrame {
  std::string image;  // images/<name>.png
  std::string label;  // labels/<name>.png (class per pixel)
};
enum CamVidClass {
  kCamVidSky = 0,
  kCamVidBuilding = 1,
  kCamVidPole = 2,
  kCamVidRoad = 3,
  kCamVidPavement = 4,
  kCamVidTree = 5,
  kCamVidSign = 6,
  kCamVidFence = 7,
  kCamVidCar = 8,
  kCamVidPedestrian = 9,
  kCamVidBicyclist = 10,
  kCamVidVoid = 11
};
Status ReadCamVid(const std::string& root, std::vector<CamVidFrame>* frames);
bool IsCamVidStaticClass(int label);   // sky, building, pole, road, pavement, tree, sign, fence
bool IsCamVidMovableClass(int label);  // car, pedestrian, bicyclist

// Where the features labelled moving fall in a CamVid label image.
struct CamVidFeatureStats {
  int moving = 0;                 // features labelled moving (inside the image) (count)
  int on_static = 0;              // ... on static classes: false detections (count)
  int on_movable = 0;             // ... on cars, pedestrians, bicyclists (count)
  int on_void = 0;                // ... on void / unknown labels (count)
  double static_fraction = 0.0;   // on_static / moving (0 if none)
  double movable_fraction = 0.0;  // on_movable / moving (0 if none)
  void Add(const CamVidFeatureStats& other);
};
CamVidFeatureStats CamVidMovingFeatureStats(const std::vector<LabelledFeature>& features,
                                            const cv::Mat& labels);

// ---------------------------------------------------------------- TUM RGB-D subset
struct TumSubset {
  Trajectory truth;                 // world_from_cam (truth_cam_poses.txt)
  std::vector<std::string> images;  // raw_imgs/NNNN_rgb_raw.jpg, one per truth pose
  std::vector<std::string> depths;  // depth_imgs/NNNN_depth_raw.png (5000 per metre)
  CameraIntrinsics intrinsics;      // freiburg3
};
Status ReadTumSubset(const std::string& root, TumSubset* subset);

// ---------------------------------------------------------------- TartanAir subset
struct TartanAirSubset {
  Trajectory truth;  // world_from_cam (world in NED, camera x right, y down, z forward)
  std::vector<std::string> images;  // images/NNNNNN_left.jpg
  CameraIntrinsics intrinsics;      // fx = fy = 320, cx = 320, cy = 240
};
// Frame i gets utime = i * frame_period_us (the data has no timestamps).
Status ReadTartanAirSubset(const std::string& root, int64_t frame_period_us,
                           TartanAirSubset* subset);

// ---------------------------------------------------------------- simulator sequence folder
struct SequenceFolder {
  CameraIntrinsics intrinsics;      // calibration.yaml
  std::vector<int64_t> utimes;      // timestamps.txt, per frame
  Trajectory camera;                // cam_trajectory.tum
  std::map<int, BodyTruth> bodies;  // objects/<id>.tum + objects.yaml
  std::vector<std::string> images;  // images/NNNNNN.png
  std::vector<std::string> masks;   // masks/NNNNNN.png (may be empty)
  std::vector<std::string> depths;  // depth/NNNNNN.exr|png (may be empty)
  std::map<int, std::vector<Eigen::Vector3d>>
      points;  // points/<id>.txt: surface samples, body frame
};
Status ReadSequenceFolder(const std::string& dir, SequenceFolder* sequence);

}  // namespace eval
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_EVAL_DATASETS_H_
