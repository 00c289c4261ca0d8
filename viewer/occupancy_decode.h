#ifndef MBSLAM_VIEWER_OCCUPANCY_DECODE_H_
#define MBSLAM_VIEWER_OCCUPANCY_DECODE_H_

#include <cstddef>
#include <cstdint>

#include "common/util/status.h"
#include "viewer/scene.h"

namespace mbslam {
namespace viewer {

// Reads an OctoMap OcTree from the bytes of OcTree::writeBinary (occupancy_t.data) and
// lists its occupied leaves (a pruned leaf is one bigger voxel), at most max_voxels of
// them; `num_occupied` counts all. Never throws; a stream that is not a tree is an error
// (read with the checks of ReadOctreeBinary, services/perception/occupancy/octree_io.h).
Status DecodeOccupancy(const uint8_t* data, size_t size, int max_voxels, OccupancyData* out);

}  // namespace viewer
}  // namespace mbslam

#endif  // MBSLAM_VIEWER_OCCUPANCY_DECODE_H_
