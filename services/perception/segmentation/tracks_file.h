#ifndef MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_TRACKS_FILE_H_
#define MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_TRACKS_FILE_H_

// Feature tracks without images (the tracks-only entry point): the plain-text
// `*.tracks.txt` format of Hopkins 155 / KT3DMoSeg exports:
//   line 1: P F width height
//   line 2: P ground-truth labels (integers)
//   P lines: x1 y1 x2 y2 ... xF yF   (pixels; "nan nan" = not visible)

#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/util/status.h"

namespace mbslam {

struct TrackSet {
  std::string name;
  int width = 0;
  int height = 0;
  int frames = 0;
  std::vector<int> labels;  // ground truth per track
  // positions[p][f]; NaN when not visible.
  std::vector<std::vector<Eigen::Vector2d>> positions;

  int num_tracks() const { return static_cast<int>(positions.size()); }
  int num_groups() const;
  // 2F x P matrix of the tracks visible in every frame (column order = track order);
  // `used` gets their indices.
  Eigen::MatrixXd CompleteTrajectoryMatrix(std::vector<int>* used) const;
};

Status ReadTrackSet(const std::string& path, TrackSet* tracks);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_TRACKS_FILE_H_
