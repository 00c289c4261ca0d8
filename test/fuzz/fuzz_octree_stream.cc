// Fuzz target: the OctoMap stream reader every PERCEPTION_OCCUPANCY subscriber uses
// (ReadOctreeBinary, services/perception/occupancy/octree_io.h; planner_example and the
// viewer's DecodeOccupancy). Input: one tag byte; tag % 2 = 0: the bytes are an
// OcTree::writeBinary stream (occupancy_t.data, a .bt file); 1: an occupancy_t
// encoding, decoded as planner_example does.
//
// Properties: nothing throws, crashes or recurses without bound; an accepted tree
// stays within 16 levels and the node limit, has a plausible resolution, and what
// OctoMap writes from it reads back.

#include <cmath>
#include <sstream>

#include "common/lcm/wire_check.h"
#include "mbslam/occupancy_t.hpp"
#include "services/perception/occupancy/octree_io.h"
#include "test/fuzz/fuzz_util.h"
#include "viewer/occupancy_decode.h"

namespace {

void ReadStream(const uint8_t* data, size_t size) {
  const mbslam::OctreeReadLimits limits;
  std::unique_ptr<octomap::OcTree> tree;
  if (mbslam::ReadOctreeBinary(data, size, limits, &tree).ok()) {
    if (!tree) mbslam::fuzz::Fail("accepted stream without a tree");
    if (static_cast<int64_t>(tree->size()) > limits.max_nodes) mbslam::fuzz::Fail("node limit exceeded");
    const double res = tree->getResolution();
    if (!std::isfinite(res) || res < limits.min_resolution || res > limits.max_resolution) {
      mbslam::fuzz::Fail("implausible resolution accepted");
    }
    for (auto it = tree->begin_tree(), end = tree->end_tree(); it != end; ++it) {
      if (it.getDepth() > tree->getTreeDepth()) mbslam::fuzz::Fail("node below the tree depth");
    }
    std::ostringstream out;
    tree->writeBinary(out);
    const std::string again = out.str();
    std::unique_ptr<octomap::OcTree> reread;
    if (!mbslam::ReadOctreeBinary(reinterpret_cast<const uint8_t*>(again.data()), again.size(),
                                  limits, &reread)
             .ok()) {
      mbslam::fuzz::Fail("what OctoMap writes from an accepted tree does not read back");
    }
  }
  mbslam::viewer::OccupancyData voxels;
  (void)mbslam::viewer::DecodeOccupancy(data, size, /*max_voxels=*/1000, &voxels);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool quiet = (mbslam::fuzz::QuietLogs(), true);
  (void)quiet;
  if (size < 1) return 0;
  if (data[0] % 2 == 0) {
    ReadStream(data + 1, size - 1);
    return 0;
  }
  mbslam::occupancy_t msg{};
  if (!mbslam::DecodeLcmMessage(data + 1, size - 1, &msg).ok()) return 0;
  ReadStream(msg.data.data(), msg.data.size());
  return 0;
}
