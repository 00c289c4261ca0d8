#include "viewer/occupancy_decode.h"

#include <octomap/OcTree.h>

#include <exception>
#include <memory>
#include <string>

#include "services/perception/occupancy/octree_io.h"

namespace mbslam {
namespace viewer {

Status DecodeOccupancy(const uint8_t* data, size_t size, int max_voxels, OccupancyData* out) {
  *out = OccupancyData();
  if (size == 0) return Status::Ok();  // no tree yet
  std::unique_ptr<octomap::OcTree> tree;
  MBSLAM_RETURN_IF_ERROR(ReadOctreeBinary(data, size, OctreeReadLimits(), &tree));
  try {
    out->resolution = tree->getResolution();
    for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it) {
      if (!tree->isNodeOccupied(*it)) continue;
      ++out->num_occupied;
      if (static_cast<int64_t>(out->voxels.size()) >= max_voxels) continue;
      const octomap::point3d c = it.getCoordinate();
      Voxel v;
      v.center = Eigen::Vector3f(c.x(), c.y(), c.z());
      v.size = static_cast<float>(it.getSize());
      out->voxels.push_back(v);
    }
  } catch (const std::exception& e) {
    *out = OccupancyData();
    return Status::Error(std::string("OcTree decode threw: ") + e.what());
  }
  return Status::Ok();
}

}  // namespace viewer
}  // namespace mbslam
