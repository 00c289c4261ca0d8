#include "services/perception/occupancy/octree_io.h"

#include <cmath>
#include <exception>
#include <sstream>
#include <string>
#include <vector>

namespace mbslam {
namespace {

constexpr char kBinaryFileHeader[] = "# Octomap OcTree binary file";
constexpr int kTreeDepth = 16;  // OcTree's fixed depth: leaves are at most at this level

// The node bits are a pre-order walk: every node read takes two bytes holding a 2-bit
// code per child (00 none, 01 free leaf, 10 occupied leaf, 11 inner child, read next).
// Walks them without recursion, checking the depth, the length and the node count.
Status CheckBinaryTreeData(const uint8_t* data, size_t size, int64_t max_nodes,
                           int64_t* num_nodes) {
  std::vector<int> pending;  // inner children still to read, per level
  size_t pos = 0;
  int64_t nodes = 1;  // the root
  auto read_node = [&](int depth) -> Status {
    if (depth >= kTreeDepth) return Status::Error("OcTree data deeper than 16 levels");
    if (size - pos < 2) return Status::Error("OcTree data ends early");
    int inner = 0;
    for (int b = 0; b < 2; ++b) {
      const uint8_t bits = data[pos + b];
      for (int i = 0; i < 4; ++i) {
        const int code = (bits >> (2 * i)) & 3;
        inner += code == 3 ? 1 : 0;
        nodes += code != 0 ? 1 : 0;
      }
    }
    if (nodes > max_nodes) {
      return Status::Error("OcTree data has more than " + std::to_string(max_nodes) + " nodes");
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
  if (pos != size) {
    return Status::Error(std::to_string(size - pos) + " bytes after the end of the OcTree data");
  }
  *num_nodes = nodes;
  return Status::Ok();
}

}  // namespace

Status ReadOctreeBinary(const uint8_t* data, size_t size, const OctreeReadLimits& limits,
                        std::unique_ptr<octomap::OcTree>* tree) {
  tree->reset();
  if (size == 0) return Status::Error("empty OcTree stream");
  try {
    std::istringstream in(std::string(reinterpret_cast<const char*>(data), size),
                          std::ios::in | std::ios::binary);
    // The text header of OcTree::writeBinary, parsed here rather than by readBinary,
    // which trusts it (and prints debug lines to stderr for every tree).
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
    if (!std::isfinite(resolution) || resolution < limits.min_resolution ||
        resolution > limits.max_resolution) {
      return Status::Error("OcTree with resolution " + std::to_string(resolution) + " m");
    }
    const std::streamoff offset = in.tellg();
    if (offset < 0 || static_cast<size_t>(offset) > size) {
      return Status::Error("OcTree header ends early");
    }
    auto result = std::make_unique<octomap::OcTree>(resolution);
    if (declared_size == 0 && static_cast<size_t>(offset) == size) {
      *tree = std::move(result);  // what writeBinary writes for an empty tree
      return Status::Ok();
    }
    int64_t num_nodes = 0;
    MBSLAM_RETURN_IF_ERROR(CheckBinaryTreeData(data + offset, size - static_cast<size_t>(offset),
                                               limits.max_nodes, &num_nodes));
    if (declared_size >= 0 && num_nodes != declared_size) {
      return Status::Error("OcTree data has " + std::to_string(num_nodes) +
                           " nodes, the header says " + std::to_string(declared_size));
    }
    result->readBinaryData(in);
    if (in.fail()) return Status::Error("OcTree data ends early");
    *tree = std::move(result);
  } catch (const std::exception& e) {
    tree->reset();
    return Status::Error(std::string("OcTree stream: ") + e.what());
  }
  return Status::Ok();
}

}  // namespace mbslam
