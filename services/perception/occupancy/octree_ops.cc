#include "services/perception/occupancy/octree_ops.h"

#include <algorithm>
#include <array>
#include <sstream>

namespace mbslam {
namespace {

constexpr unsigned kTreeDepth = 16;  // OctoMap's fixed depth (16-bit keys)

// Spreads the 16 low bits of x to every third bit.
uint64_t SpreadBits(uint64_t x) {
  x &= 0xffffu;
  x = (x | (x << 32)) & 0x001f00000000ffffULL;
  x = (x | (x << 16)) & 0x001f0000ff0000ffULL;
  x = (x | (x << 8)) & 0x100f00f00f00f00fULL;
  x = (x | (x << 4)) & 0x10c30c30c30c30c3ULL;
  x = (x | (x << 2)) & 0x1249249249249249ULL;
  return x;
}

uint16_t CompactBits(uint64_t x) {
  x &= 0x1249249249249249ULL;
  x = (x | (x >> 2)) & 0x10c30c30c30c30c3ULL;
  x = (x | (x >> 4)) & 0x100f00f00f00f00fULL;
  x = (x | (x >> 8)) & 0x001f0000ff0000ffULL;
  x = (x | (x >> 16)) & 0x001f00000000ffffULL;
  x = (x | (x >> 32)) & 0xffffULL;
  return static_cast<uint16_t>(x);
}

// State of a node in the maximum-likelihood, pruned view of the tree.
enum NodeState : uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2, kInner = 3 };

NodeState LeafState(const octomap::OcTree& tree, const octomap::OcTreeNode* node) {
  return tree.isNodeOccupied(node) ? kOccupied : kFree;
}

using CollapseCounts = std::array<uint64_t, kTreeDepth + 1>;

// Writes the node's two bytes and its inner children (OctoMap's writeBinaryNode) for the
// maximum-likelihood tree, collapsing nodes deeper than `cutoff` whose eight children
// are leaves of one state, the way prune() does after toMaxLikelihood(); counts the
// collapses per depth. A node that collapses writes nothing and returns its leaf state.
NodeState WriteNode(const octomap::OcTree& tree, const octomap::OcTreeNode* node, unsigned depth,
                    unsigned cutoff, std::string* out, uint64_t* num_nodes,
                    CollapseCounts* counts) {
  const size_t header = out->size();
  out->append(2, '\0');
  std::array<NodeState, 8> states{};
  bool collapsible = depth > cutoff && depth > 0;
  NodeState first = kUnknown;
  uint64_t children = 0;
  for (unsigned i = 0; i < 8; ++i) {
    if (!tree.nodeChildExists(node, i)) {
      states[i] = kUnknown;
      collapsible = false;
      continue;
    }
    ++children;
    const octomap::OcTreeNode* child = tree.getNodeChild(node, i);
    if (!tree.nodeHasChildren(child)) {
      states[i] = LeafState(tree, child);
    } else {
      const size_t before = out->size();
      const uint64_t nodes_before = *num_nodes;
      states[i] = WriteNode(tree, child, depth + 1, cutoff, out, num_nodes, counts);
      if (states[i] != kInner) {  // collapsed: written as a leaf of this node
        out->resize(before);
        *num_nodes = nodes_before;
      }
    }
    if (states[i] == kInner || (first != kUnknown && states[i] != first)) {
      collapsible = false;
    }
    if (first == kUnknown) {
      first = states[i];
    }
  }
  if (collapsible) {
    out->resize(header);
    ++(*counts)[depth];
    return first;
  }
  // Two bits per child, children 0-3 in the first byte, child i at bits 2i (low) and
  // 2i+1 (high) of its byte: 3 inner node, 2 occupied leaf, 1 free leaf, 0 unknown.
  uint8_t bytes[2] = {0, 0};
  for (unsigned i = 0; i < 8; ++i) {
    const unsigned bit = 2 * (i % 4);
    uint8_t pair = 0;
    switch (states[i]) {
      case kInner:
        pair = 3;
        break;
      case kOccupied:
        pair = 2;
        break;
      case kFree:
        pair = 1;
        break;
      case kUnknown:
        pair = 0;
        break;
    }
    bytes[i / 4] = static_cast<uint8_t>(bytes[i / 4] | (pair << bit));
  }
  (*out)[header] = static_cast<char>(bytes[0]);
  (*out)[header + 1] = static_cast<char>(bytes[1]);
  *num_nodes += children;
  return kInner;
}

}  // namespace

uint64_t OctreeMortonCode(const octomap::OcTreeKey& key) {
  return SpreadBits(key[0]) | (SpreadBits(key[1]) << 1) | (SpreadBits(key[2]) << 2);
}

octomap::OcTreeKey OctreeKeyOfMortonCode(uint64_t code) {
  return octomap::OcTreeKey(CompactBits(code), CompactBits(code >> 1), CompactBits(code >> 2));
}

int64_t ApplyVoxelUpdates(octomap::OcTree* tree, std::vector<uint64_t>* updates, float weak_hit_log_odds) {
  std::vector<uint64_t>& u = *updates;
  if (u.empty()) {
    return 0;
  }
  std::sort(u.begin(), u.end());
  const float hit = static_cast<float>(tree->getProbHitLog());
  const float miss = static_cast<float>(tree->getProbMissLog());
  const float clamp_min = static_cast<float>(tree->getClampingThresMinLog());
  const float clamp_max = static_cast<float>(tree->getClampingThresMaxLog());
  const float occupied = static_cast<float>(tree->getOccupancyThresLog());
  // OctoMap's early abort: a node already clamped in the update's direction stays.
  auto saturated = [&](const octomap::OcTreeNode* node, bool is_hit) {
    return is_hit ? node->getLogOdds() >= clamp_max : node->getLogOdds() <= clamp_min;
  };

  size_t i = 0;
  // The next voxel, whether any of its entries is a (weak) hit and the log-odds change
  // (sorted: the strongest kind comes last).
  float change = miss;
  auto next = [&](uint64_t* code, bool* is_hit) {
    *code = u[i] >> 2;
    while (i + 1 < u.size() && (u[i + 1] >> 2) == *code) {
      ++i;
    }
    const unsigned kind = static_cast<unsigned>(u[i] & 3u);
    *is_hit = kind != 0;
    change = kind == 2 ? hit : (kind == 1 ? weak_hit_log_odds : miss);
    ++i;
  };

  int64_t delta = 0;
  uint64_t code = 0;
  bool is_hit = false;
  if (tree->getRoot() == nullptr) {
    // The first voxel of an empty tree goes through OctoMap, which creates the root.
    next(&code, &is_hit);
    const octomap::OcTreeKey key = OctreeKeyOfMortonCode(code);
    tree->updateNode(key, change, /*lazy_eval=*/false);
    const octomap::OcTreeNode* leaf = tree->search(key);
    if (leaf != nullptr && tree->isNodeOccupied(leaf)) {
      ++delta;
    }
  }

  // path[d]: the node at depth d on the way to the previous voxel, valid to depth
  // `valid`; created[d]: that node was created on this walk and has no children yet.
  std::array<octomap::OcTreeNode*, kTreeDepth + 1> path{};
  std::array<bool, kTreeDepth + 1> created{};
  path[0] = tree->getRoot();
  unsigned valid = 0;
  bool have_previous = false;
  uint64_t previous = 0;
  // A node is finished once the walk leaves its subtree (depth-first order): prune it or
  // set it to the maximum of its children, as OctoMap's non-lazy update does.
  auto finish = [&](unsigned deepest, unsigned shallowest) {
    for (unsigned d = std::min(deepest, kTreeDepth - 1) + 1; d-- > shallowest;) {
      octomap::OcTreeNode* node = path[d];
      if (!tree->nodeHasChildren(node)) {
        continue;
      }
      if (!tree->pruneNode(node)) {
        node->updateOccupancyChildren();
      }
    }
  };

  while (i < u.size()) {
    next(&code, &is_hit);
    unsigned common = 0;
    if (have_previous) {
      const int level = (63 - __builtin_clzll(code ^ previous)) / 3;  // highest differing level
      common = std::min(kTreeDepth - 1 - static_cast<unsigned>(level), valid);
      if (valid > common) {
        finish(valid, common + 1);
      }
    }
    have_previous = true;
    previous = code;

    unsigned d = common;
    bool aborted = false;
    for (; d < kTreeDepth; ++d) {
      octomap::OcTreeNode* node = path[d];
      const unsigned pos = static_cast<unsigned>(code >> (3 * (kTreeDepth - 1 - d))) & 7u;
      created[d + 1] = false;
      if (!tree->nodeChildExists(node, pos)) {
        if (!tree->nodeHasChildren(node) && !created[d]) {
          // A pruned leaf covering this voxel.
          if (saturated(node, is_hit)) {
            aborted = true;
            break;
          }
          tree->expandNode(node);
        } else {
          tree->createNodeChild(node, pos);
          created[d + 1] = true;
        }
      }
      path[d + 1] = tree->getNodeChild(node, pos);
    }
    valid = d;
    if (aborted) {
      continue;
    }
    octomap::OcTreeNode* leaf = path[kTreeDepth];
    const bool was_occupied = !created[kTreeDepth] && leaf->getLogOdds() >= occupied;
    if (!saturated(leaf, is_hit)) {
      tree->updateNodeLogOdds(leaf, change);
    }
    const bool is_occupied = leaf->getLogOdds() >= occupied;
    delta += static_cast<int>(is_occupied) - static_cast<int>(was_occupied);
  }
  if (have_previous) {
    finish(valid, 0);
  }
  return delta;
}

namespace {

// An OcTree whose root can be created directly (OctoMap creates it only inside its
// update functions). Behaves as an octomap::OcTree in every other way.
class CroppedOcTree : public octomap::OcTree {
 public:
  using octomap::OcTree::OcTree;
  octomap::OcTreeNode* CreateRoot() {
    root = new octomap::OcTreeNode();
    ++tree_size;
    size_changed = true;
    return root;
  }
};

// Key range of a node at `depth` whose first (lowest) key is `lo`: [lo, lo + span).
struct NodeBox {
  std::array<unsigned, 3> lo;
  unsigned span;
};

bool Overlaps(const NodeBox& b, const octomap::OcTreeKey& min_key, const octomap::OcTreeKey& max_key) {
  for (int i = 0; i < 3; ++i) {
    if (b.lo[i] > max_key[i] || b.lo[i] + b.span - 1 < min_key[i]) return false;
  }
  return true;
}

bool Inside(const NodeBox& b, const octomap::OcTreeKey& min_key, const octomap::OcTreeKey& max_key) {
  for (int i = 0; i < 3; ++i) {
    if (b.lo[i] < min_key[i] || b.lo[i] + b.span - 1 > max_key[i]) return false;
  }
  return true;
}

NodeBox ChildBox(const NodeBox& b, unsigned pos) {
  NodeBox c;
  c.span = b.span / 2;
  for (int i = 0; i < 3; ++i) c.lo[i] = b.lo[i] + (((pos >> i) & 1u) ? c.span : 0u);
  return c;
}

size_t CountSubtree(const octomap::OcTree& tree, const octomap::OcTreeNode* node) {
  size_t n = 1;
  if (!tree.nodeHasChildren(node)) return n;
  for (unsigned pos = 0; pos < 8; ++pos) {
    if (tree.nodeChildExists(node, pos)) n += CountSubtree(tree, tree.getNodeChild(node, pos));
  }
  return n;
}

// True when the subtree of `node` (box `b`) has a leaf overlapping the key box.
bool HasLeafInBox(const octomap::OcTree& tree, const octomap::OcTreeNode* node, const NodeBox& b,
                  const octomap::OcTreeKey& min_key, const octomap::OcTreeKey& max_key) {
  if (!Overlaps(b, min_key, max_key)) return false;
  if (!tree.nodeHasChildren(node) || Inside(b, min_key, max_key)) return true;
  for (unsigned pos = 0; pos < 8; ++pos) {
    if (tree.nodeChildExists(node, pos) &&
        HasLeafInBox(tree, tree.getNodeChild(node, pos), ChildBox(b, pos), min_key, max_key)) {
      return true;
    }
  }
  return false;
}

// Copies the overlapping part of `src` (box `b`, known to hold a leaf in the key box)
// into the existing node `dst`; with dst_tree == nullptr only counts the nodes a copy
// would have (`num_nodes`).
void CopyOverlap(const octomap::OcTree& src_tree, const octomap::OcTreeNode* src, const NodeBox& b,
                 const octomap::OcTreeKey& min_key, const octomap::OcTreeKey& max_key, bool inside,
                 octomap::OcTree* dst_tree, octomap::OcTreeNode* dst, int64_t* num_occupied, size_t* num_nodes) {
  ++*num_nodes;
  if (!src_tree.nodeHasChildren(src)) {
    if (dst != nullptr) dst->setLogOdds(src->getLogOdds());
    if (src_tree.isNodeOccupied(src)) *num_occupied += int64_t{1} << (3 * (63 - __builtin_clzll(b.span)));
    return;
  }
  for (unsigned pos = 0; pos < 8; ++pos) {
    if (!src_tree.nodeChildExists(src, pos)) continue;
    const octomap::OcTreeNode* child = src_tree.getNodeChild(src, pos);
    const NodeBox cb = ChildBox(b, pos);
    const bool child_inside = inside || Inside(cb, min_key, max_key);
    if (!child_inside && !HasLeafInBox(src_tree, child, cb, min_key, max_key)) continue;
    if (child_inside && dst == nullptr) {
      *num_nodes += CountSubtree(src_tree, child);
      continue;
    }
    octomap::OcTreeNode* d = dst != nullptr ? dst_tree->createNodeChild(dst, pos) : nullptr;
    CopyOverlap(src_tree, child, cb, min_key, max_key, child_inside, dst_tree, d, num_occupied, num_nodes);
  }
  if (dst != nullptr) dst->updateOccupancyChildren();
}

}  // namespace

std::unique_ptr<octomap::OcTree> CropOctree(const octomap::OcTree& tree, const octomap::OcTreeKey& min_key,
                                            const octomap::OcTreeKey& max_key, int64_t* num_occupied) {
  auto out = std::make_unique<CroppedOcTree>(tree.getResolution());
  out->setProbHit(tree.getProbHit());
  out->setProbMiss(tree.getProbMiss());
  out->setClampingThresMin(tree.getClampingThresMin());
  out->setClampingThresMax(tree.getClampingThresMax());
  out->setOccupancyThres(tree.getOccupancyThres());
  int64_t occupied = 0;
  const octomap::OcTreeNode* root = tree.getRoot();
  const NodeBox box{{0u, 0u, 0u}, 1u << kTreeDepth};
  size_t nodes = 0;
  if (root != nullptr && HasLeafInBox(tree, root, box, min_key, max_key)) {
    CopyOverlap(tree, root, box, min_key, max_key, Inside(box, min_key, max_key), out.get(), out->CreateRoot(),
                &occupied, &nodes);
  }
  if (num_occupied != nullptr) *num_occupied = occupied;
  return out;
}

size_t CountCropNodes(const octomap::OcTree& tree, const octomap::OcTreeKey& min_key,
                      const octomap::OcTreeKey& max_key) {
  const octomap::OcTreeNode* root = tree.getRoot();
  const NodeBox box{{0u, 0u, 0u}, 1u << kTreeDepth};
  size_t nodes = 0;
  int64_t occupied = 0;
  if (root != nullptr && HasLeafInBox(tree, root, box, min_key, max_key)) {
    CopyOverlap(tree, root, box, min_key, max_key, Inside(box, min_key, max_key), nullptr, nullptr, &occupied,
                &nodes);
  }
  return nodes;
}

void WriteOctreeBinary(const octomap::OcTree& tree, std::string* out) {
  const octomap::OcTreeNode* root = tree.getRoot();
  std::string data;
  uint64_t num_nodes = 0;
  if (root != nullptr) {
    num_nodes = 1;
    if (!tree.nodeHasChildren(root)) {
      data.assign(2, '\0');
    } else {
      // OcTree::prune() collapses depth 15, then 14, ... and stops at the first depth
      // where nothing collapsed: nodes above that depth stay as they are. Write with
      // collapses at every depth first; in the rare case that this collapsed a node
      // above the first empty depth, write again with that cutoff.
      CollapseCounts counts{};
      WriteNode(tree, root, 0, 0, &data, &num_nodes, &counts);
      unsigned cutoff = 0;
      for (unsigned d = kTreeDepth - 1; d > 0; --d) {
        if (counts[d] == 0) {
          cutoff = d;
          break;
        }
      }
      bool collapsed_above = false;
      for (unsigned d = 1; d < cutoff; ++d) {
        collapsed_above = collapsed_above || counts[d] > 0;
      }
      if (collapsed_above) {
        data.clear();
        num_nodes = 1;
        counts.fill(0);
        WriteNode(tree, root, 0, cutoff, &data, &num_nodes, &counts);
      }
    }
  }
  std::ostringstream header;
  header << "# Octomap OcTree binary file\n"
         << "# (feel free to add / change comments, but leave the first line as it is!)\n"
         << "#\n"
         << "id " << tree.getTreeType() << "\n"
         << "size " << num_nodes << "\n"
         << "res " << tree.getResolution() << "\n"
         << "data\n";
  out->append(header.str());
  out->append(data);
}

}  // namespace mbslam
