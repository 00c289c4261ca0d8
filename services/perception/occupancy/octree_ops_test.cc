#include "services/perception/occupancy/octree_ops.h"

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace mbslam {
namespace {

std::string OctomapWriteBinary(const octomap::OcTree& tree) {
  octomap::OcTree copy(tree);
  std::ostringstream out;
  EXPECT_TRUE(copy.writeBinary(out));
  return out.str();
}

std::string OurWriteBinary(const octomap::OcTree& tree) {
  std::string out;
  WriteOctreeBinary(tree, &out);
  return out;
}

int64_t CountOccupied(const octomap::OcTree& tree) {
  int64_t n = 0;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    if (tree.isNodeOccupied(*it)) {
      n += int64_t{1} << (3 * (16 - it.getDepth()));
    }
  }
  return n;
}

// Random scans: rays from a moving origin to points on a few planes and in the open.
octomap::Pointcloud Scan(std::mt19937* rng, const octomap::point3d& origin, int n) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  octomap::Pointcloud cloud;
  for (int i = 0; i < n; ++i) {
    const float a = u(*rng), b = u(*rng), c = u(*rng);
    switch (i % 3) {
      case 0:
        cloud.push_back(origin.x() + 4.0f + 0.2f * c, origin.y() + 3.0f * a, 1.0f + b);
        break;
      case 1:
        cloud.push_back(origin.x() + 3.0f * a + 2.0f, origin.y() + 3.0f * b, 0.0f);
        break;
      default:
        cloud.push_back(origin.x() + 9.0f * a, origin.y() + 9.0f * b, 3.0f * c);
        break;
    }
  }
  return cloud;
}

// The update step of insertPointCloud, through ApplyVoxelUpdates.
int64_t Insert(octomap::OcTree* tree, const octomap::Pointcloud& cloud,
               const octomap::point3d& origin, double max_range) {
  octomap::KeySet free_cells, occupied_cells;
  tree->computeUpdate(cloud, origin, free_cells, occupied_cells, max_range);
  std::vector<uint64_t> updates;
  for (const auto& k : free_cells) {
    updates.push_back(VoxelUpdate(k, false));
  }
  for (const auto& k : occupied_cells) {
    updates.push_back(VoxelUpdate(k, true));
  }
  return ApplyVoxelUpdates(tree, &updates);
}

TEST(OctreeOps, MortonCodeRoundTripsAndOrdersChildren) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> u(0, 65535);
  for (int i = 0; i < 1000; ++i) {
    const octomap::OcTreeKey key(u(rng), u(rng), u(rng));
    EXPECT_EQ(OctreeKeyOfMortonCode(OctreeMortonCode(key)), key);
    // The top three bits are the child index at the root, as OctoMap computes it.
    EXPECT_EQ(OctreeMortonCode(key) >> 45, octomap::computeChildIdx(key, 15));
    EXPECT_EQ(OctreeMortonCode(key) & 7u, octomap::computeChildIdx(key, 0));
  }
}

TEST(OctreeOps, UpdatesGiveTheSameTreeAsInsertPointCloud) {
  for (const double resolution : {0.1, 0.25}) {
    for (const double max_range : {-1.0, 6.0}) {
      octomap::OcTree ours(resolution), reference(resolution);
      std::mt19937 rng(11);
      int64_t occupied = 0;
      for (int k = 0; k < 25; ++k) {
        const octomap::point3d origin(0.3f * k + 0.01f, 0.1f * (k % 3), 1.2f);
        const octomap::Pointcloud cloud = Scan(&rng, origin, 150);
        occupied += Insert(&ours, cloud, origin, max_range);
        reference.insertPointCloud(cloud, origin, max_range);
      }
      ASSERT_EQ(ours.size(), reference.size()) << resolution << " " << max_range;
      size_t mismatches = 0, leaves = 0;
      for (auto it = reference.begin_leafs(); it != reference.end_leafs(); ++it) {
        ++leaves;
        const octomap::OcTreeNode* node = ours.search(it.getKey(), it.getDepth());
        if (node == nullptr || node->getLogOdds() != it->getLogOdds()) {
          ++mismatches;
        }
      }
      EXPECT_GT(leaves, 1000u);
      EXPECT_EQ(mismatches, 0u);
      EXPECT_EQ(occupied, CountOccupied(reference));
      std::ostringstream a, b;
      ours.writeBinaryConst(a);
      reference.writeBinaryConst(b);
      EXPECT_EQ(a.str(), b.str());
      // Inner nodes hold the maximum of their children, as after a non-lazy update.
      EXPECT_FLOAT_EQ(ours.getRoot()->getLogOdds(), reference.getRoot()->getLogOdds());
    }
  }
}

TEST(OctreeOps, SaturatedAndPrunedRegions) {
  // A block hit again and again saturates, its voxels prune into bigger leaves, and
  // later rays through it (misses) must expand them exactly as OctoMap does.
  octomap::OcTree ours(0.1), reference(0.1);
  octomap::Pointcloud block;
  for (int i = 0; i < 16; ++i) {
    for (int j = 0; j < 16; ++j) {
      for (int k = 0; k < 16; ++k) {
        block.push_back(2.05f + 0.1f * i, 0.05f + 0.1f * j, 0.05f + 0.1f * k);
      }
    }
  }
  const octomap::point3d origin(0.05f, 0.05f, 0.05f);
  int64_t occupied = 0;
  for (int n = 0; n < 8; ++n) {
    occupied += Insert(&ours, block, origin, -1.0);
    reference.insertPointCloud(block, origin, -1.0);
  }
  // Rays through the block from the other side.
  octomap::Pointcloud through;
  for (int j = 0; j < 16; ++j) {
    through.push_back(1.0f, 0.05f + 0.1f * j, 0.75f);
  }
  const octomap::point3d far_origin(6.05f, 0.75f, 0.75f);
  for (int n = 0; n < 3; ++n) {
    occupied += Insert(&ours, through, far_origin, -1.0);
    reference.insertPointCloud(through, far_origin, -1.0);
  }
  EXPECT_LT(reference.size(), 16u * 16u * 16u);  // pruning happened
  EXPECT_EQ(ours.size(), reference.size());
  EXPECT_EQ(occupied, CountOccupied(reference));
  std::ostringstream a, b;
  ours.writeBinaryConst(a);
  reference.writeBinaryConst(b);
  EXPECT_EQ(a.str(), b.str());
  EXPECT_EQ(OurWriteBinary(ours), OctomapWriteBinary(reference));
}

TEST(OctreeOps, WriteBinaryMatchesOctomap) {
  // Empty tree.
  octomap::OcTree empty(0.2);
  EXPECT_EQ(OurWriteBinary(empty), OctomapWriteBinary(empty));
  // Random scans at several resolutions, with and without a range bound.
  for (const double resolution : {0.05, 0.1, 0.123456789}) {
    octomap::OcTree tree(resolution);
    std::mt19937 rng(5);
    for (int k = 0; k < 15; ++k) {
      const octomap::point3d origin(0.2f * k, 0.0f, 1.0f);
      tree.insertPointCloud(Scan(&rng, origin, 200), origin, k % 2 ? 5.0 : -1.0);
      if (k % 4 != 3) {
        continue;
      }
      ASSERT_EQ(OurWriteBinary(tree), OctomapWriteBinary(tree)) << resolution << " scan " << k;
    }
    // And it reads back.
    octomap::OcTree read(1.0);
    std::istringstream in(OurWriteBinary(tree));
    ASSERT_TRUE(read.readBinary(in));
    EXPECT_EQ(CountOccupied(read), CountOccupied(tree));
  }
  // Eight pruned blocks of 2x2x2 voxels, all occupied but each with its own log-odds:
  // after toMaxLikelihood() they could merge into one leaf, but OcTree::prune() stops at
  // depth 15, where nothing collapses, so writeBinary keeps them apart.
  octomap::OcTree blocks(0.1);
  for (int b = 0; b < 8; ++b) {
    for (int v = 0; v < 8; ++v) {
      const int x = 2 * (b & 1) + (v & 1), y = 2 * ((b >> 1) & 1) + ((v >> 1) & 1),
                z = 2 * ((b >> 2) & 1) + ((v >> 2) & 1);
      blocks.setNodeValue(octomap::point3d(0.05f + 0.1f * x, 0.05f + 0.1f * y, 0.05f + 0.1f * z),
                          1.0f + 0.1f * b);
    }
  }
  EXPECT_EQ(OurWriteBinary(blocks), OctomapWriteBinary(blocks));
  // A single voxel.
  octomap::OcTree one(0.1);
  one.updateNode(octomap::point3d(0.05f, 0.05f, 0.05f), true);
  EXPECT_EQ(OurWriteBinary(one), OctomapWriteBinary(one));
}

// A tree from a few scans along a line (free space, walls, floor; pruned regions).
octomap::OcTree ScannedTree(double resolution) {
  octomap::OcTree tree(resolution);
  std::mt19937 rng(11);
  for (int s = 0; s < 12; ++s) {
    const octomap::point3d origin(0.5f * static_cast<float>(s), 0.1f * static_cast<float>(s), 0.5f);
    Insert(&tree, Scan(&rng, origin, 400), origin, 8.0);
  }
  return tree;
}

TEST(OctreeOps, CropToEverythingIsTheSameTree) {
  const octomap::OcTree tree = ScannedTree(0.1);
  int64_t occupied = -1;
  const auto copy = CropOctree(tree, octomap::OcTreeKey(0, 0, 0), octomap::OcTreeKey(65535, 65535, 65535), &occupied);
  EXPECT_EQ(OurWriteBinary(*copy), OurWriteBinary(tree));
  EXPECT_EQ(copy->size(), tree.size());
  EXPECT_EQ(CountCropNodes(tree, octomap::OcTreeKey(0, 0, 0), octomap::OcTreeKey(65535, 65535, 65535)), tree.size());
  EXPECT_EQ(copy->getNumLeafNodes(), tree.getNumLeafNodes());
  EXPECT_EQ(occupied, CountOccupied(tree));
  EXPECT_EQ(copy->memoryUsage(), tree.memoryUsage());
  // Probabilities, not only the maximum-likelihood tree: every leaf has the same value.
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    const octomap::OcTreeNode* n = copy->search(it.getKey(), it.getDepth());
    ASSERT_NE(n, nullptr);
    EXPECT_EQ(n->getLogOdds(), it->getLogOdds());
  }
  EXPECT_DOUBLE_EQ(copy->getProbHit(), tree.getProbHit());
  EXPECT_DOUBLE_EQ(copy->getClampingThresMax(), tree.getClampingThresMax());
}

TEST(OctreeOps, CropKeepsTheBoxAndDropsTheRest) {
  const octomap::OcTree tree = ScannedTree(0.1);
  octomap::OcTreeKey c;
  ASSERT_TRUE(tree.coordToKeyChecked(octomap::point3d(2.0f, 0.5f, 0.5f), c));
  const int half = 20;
  const octomap::OcTreeKey lo(c[0] - half, c[1] - half, c[2] - half);
  const octomap::OcTreeKey hi(c[0] + half, c[1] + half, c[2] + half);
  int64_t occupied = -1;
  const auto crop = CropOctree(tree, lo, hi, &occupied);
  EXPECT_LT(crop->size(), tree.size());
  EXPECT_GT(crop->size(), 0u);
  EXPECT_EQ(CountCropNodes(tree, lo, hi), crop->size());
  EXPECT_EQ(occupied, CountOccupied(*crop));
  // Inside the box: the same value at the finest resolution as the original.
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> u(-half, half);
  int known = 0;
  for (int i = 0; i < 3000; ++i) {
    const octomap::OcTreeKey k(c[0] + u(rng), c[1] + u(rng), c[2] + u(rng));
    const octomap::OcTreeNode* a = tree.search(k);
    const octomap::OcTreeNode* b = crop->search(k);
    ASSERT_EQ(a == nullptr, b == nullptr);
    if (a != nullptr) {
      EXPECT_EQ(a->getLogOdds(), b->getLogOdds());
      ++known;
    }
  }
  EXPECT_GT(known, 100);
  // Every kept leaf overlaps the box.
  for (auto it = crop->begin_leafs(); it != crop->end_leafs(); ++it) {
    const unsigned span = 1u << (16 - it.getDepth());
    const octomap::OcTreeKey k = it.getIndexKey();
    for (int a = 0; a < 3; ++a) {
      EXPECT_LE(k[a], hi[a]);
      EXPECT_GE(k[a] + span - 1, lo[a]);
    }
  }
  // Inner nodes hold the maximum of their children, as after OctoMap's own updates: the
  // maximum-likelihood writer of the crop agrees with OctoMap's.
  EXPECT_EQ(OurWriteBinary(*crop), OctomapWriteBinary(*crop));
}

TEST(OctreeOps, CropOfAnEmptyRegionOrTreeIsEmpty) {
  const octomap::OcTree tree = ScannedTree(0.1);
  int64_t occupied = -1;
  const auto far = CropOctree(tree, octomap::OcTreeKey(0, 0, 0), octomap::OcTreeKey(10, 10, 10), &occupied);
  EXPECT_EQ(far->size(), 0u);
  EXPECT_EQ(far->getRoot(), nullptr);
  EXPECT_EQ(occupied, 0);
  const octomap::OcTree empty(0.1);
  const auto none = CropOctree(empty, octomap::OcTreeKey(0, 0, 0), octomap::OcTreeKey(65535, 65535, 65535), nullptr);
  EXPECT_EQ(none->size(), 0u);
}

}  // namespace
}  // namespace mbslam
