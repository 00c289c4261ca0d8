#ifndef MBSLAM_SERVICES_PERCEPTION_OCCUPANCY_OCTREE_IO_H_
#define MBSLAM_SERVICES_PERCEPTION_OCCUPANCY_OCTREE_IO_H_

// Reading an OctoMap OcTree from the bytes OcTree::writeBinary writes (occupancy_t.data,
// occupancy.bt) when the bytes come from outside: PERCEPTION_OCCUPANCY subscribers (the
// viewer, planners) and tools reading .bt files.
//
// OcTree::readBinary trusts its input: it recurses once per inner node without a depth
// limit (a crafted stream overflows the stack or builds nodes below the tree's 16
// levels), reads past the end of a short stream into uninitialised bytes, accepts any
// resolution, and allocates about 100 bytes of nodes per 2 bytes of input. The reader
// here checks the header, the resolution, the depth, the length and the node count by
// walking the stream without recursion, and only then lets OctoMap build the tree.

#include <octomap/OcTree.h>

#include <cstddef>
#include <cstdint>
#include <memory>

#include "common/util/status.h"

namespace mbslam {

struct OctreeReadLimits {
  int64_t max_nodes = int64_t{1} << 23;  // nodes the tree may have (count); 8 M nodes take ~250 MB
  double min_resolution = 1e-4;          // smallest accepted voxel size (m)
  double max_resolution = 1e3;           // largest accepted voxel size (m)
};

// Reads `data` (the whole writeBinary output: text header, then the node bits) into a
// new tree. Never throws. An empty input is an error (no tree).
Status ReadOctreeBinary(const uint8_t* data, size_t size, const OctreeReadLimits& limits,
                        std::unique_ptr<octomap::OcTree>* tree);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_OCCUPANCY_OCTREE_IO_H_
