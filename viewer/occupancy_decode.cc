#include "viewer/occupancy_decode.h"

#include <octomap/OcTree.h>

#include <cmath>
#include <exception>
#include <sstream>
#include <string>
#include <vector>

namespace mbslam {
namespace viewer {
namespace {

constexpr char kBinaryFileHeader[] = "# Octomap OcTree binary file";
constexpr int kTreeDepth = 16;  // OcTree's fixed depth: leaves are at most at this level

// OcTree::readBinaryData trusts its input: it recurses once per inner node without a
// depth limit, so a crafted stream could overflow the stack. The stream is a pre-order
// walk in which every inner node takes two bytes holding a 2-bit code per child (binary
// 11 = inner child, read next). This walk checks depth and length without recursion.
Status CheckBinaryTreeData(const uint8_t* data, size_t size) {
  std::vector<int> pending;  // inner children still to read, per level
  size_t pos = 0;
  auto read_node = [&](int depth) -> Status {
    if (depth >= kTreeDepth) return Status::Error("OcTree data deeper than 16 levels");
    if (pos + 2 > size) return Status::Error("OcTree data ends early");
    int inner = 0;
    for (int b = 0; b < 2; ++b) {
      const uint8_t bits = data[pos + b];
      for (int i = 0; i < 4; ++i) inner += ((bits >> (2 * i)) & 3) == 3 ? 1 : 0;
    }
    pos += 2;
    pending.push_back(inner);
    return Status::Ok();
  };
  MBSLAM_RETURN_IF_ERROR(read_node(0));
  while (!pending.empty()) {
    if (pending.back() == 0) {
      pending.pop_back();
      continue;
    }
    --pending.back();
    MBSLAM_RETURN_IF_ERROR(read_node(static_cast<int>(pending.size())));
  }
  return Status::Ok();
}

}  // namespace

Status DecodeOccupancy(const uint8_t* data, size_t size, int max_voxels, OccupancyData* out) {
  *out = OccupancyData();
  if (size == 0) return Status::Ok();  // no tree yet
  try {
    std::istringstream in(std::string(reinterpret_cast<const char*>(data), size),
                          std::ios::in | std::ios::binary);
    // The text header of OcTree::writeBinary, parsed here rather than by readBinary,
    // which prints debug lines to stderr for every tree.
    std::string line;
    if (!std::getline(in, line) || line.rfind(kBinaryFileHeader, 0) != 0) {
      return Status::Error("not an OctoMap binary OcTree stream");
    }
    std::string id;
    int64_t declared_size = -1;
    double resolution = 0.0;
    bool at_data = false;
    for (int lines = 0; lines < 64 && !at_data && std::getline(in, line); ++lines) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream fields(line);
      std::string key;
      fields >> key;
      if (key == "id") {
        fields >> id;
      } else if (key == "size") {
        fields >> declared_size;
      } else if (key == "res") {
        fields >> resolution;
      } else if (key == "data") {
        at_data = true;
      }
    }
    if (!at_data) return Status::Error("OcTree header without 'data'");
    if (id != "OcTree") return Status::Error("tree type '" + id + "' is not OcTree");
    if (!(resolution > 0.0) || !std::isfinite(resolution)) {
      return Status::Error("OcTree with resolution " + std::to_string(resolution));
    }
    const size_t offset = static_cast<size_t>(in.tellg());
    if (offset > size) return Status::Error("OcTree header ends early");
    MBSLAM_RETURN_IF_ERROR(CheckBinaryTreeData(data + offset, size - offset));
    octomap::OcTree tree(resolution);
    tree.readBinaryData(in);
    if (in.fail()) return Status::Error("OcTree data ends early");
    if (declared_size >= 0 && static_cast<int64_t>(tree.size()) != declared_size) {
      return Status::Error("OcTree has " + std::to_string(tree.size()) + " nodes, header says " +
                           std::to_string(declared_size));
    }
    out->resolution = resolution;
    for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
      if (!tree.isNodeOccupied(*it)) continue;
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
