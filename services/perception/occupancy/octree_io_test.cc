#include "services/perception/occupancy/octree_io.h"

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <sstream>
#include <string>
#include <vector>

#include "services/perception/occupancy/octree_ops.h"

namespace mbslam {
namespace {

std::string Header(const std::string& size, const std::string& res) {
  return "# Octomap OcTree binary file\n# comment\nid OcTree\nsize " + size + "\nres " + res +
         "\ndata\n";
}

Status Read(const std::string& bytes, std::unique_ptr<octomap::OcTree>* tree,
            const OctreeReadLimits& limits = OctreeReadLimits()) {
  return ReadOctreeBinary(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), limits,
                          tree);
}

octomap::OcTree SmallTree() {
  octomap::OcTree tree(0.1);
  for (int i = 0; i < 20; ++i) {
    tree.updateNode(octomap::point3d(0.05f * static_cast<float>(i), 0.3f, -0.2f), true);
    tree.updateNode(octomap::point3d(-0.5f, 0.05f * static_cast<float>(i), 0.1f), false);
  }
  return tree;
}

TEST(ReadOctreeBinary, ReadsWhatOctoMapWrites) {
  octomap::OcTree tree = SmallTree();
  std::ostringstream out;
  ASSERT_TRUE(tree.writeBinary(out));
  std::unique_ptr<octomap::OcTree> read;
  ASSERT_TRUE(Read(out.str(), &read).ok());
  ASSERT_NE(read, nullptr);
  EXPECT_DOUBLE_EQ(read->getResolution(), 0.1);
  EXPECT_EQ(read->size(), tree.size());
  std::string again;
  WriteOctreeBinary(*read, &again);
  EXPECT_EQ(again, out.str());
}

TEST(ReadOctreeBinary, ReadsAnEmptyTree) {
  octomap::OcTree empty(0.2);
  std::string bytes;
  WriteOctreeBinary(empty, &bytes);
  std::unique_ptr<octomap::OcTree> read;
  ASSERT_TRUE(Read(bytes, &read).ok());
  EXPECT_EQ(read->size(), 0u);
}

TEST(ReadOctreeBinary, RejectsTruncationTrailingBytesAndWrongSize) {
  octomap::OcTree tree = SmallTree();
  std::ostringstream out;
  ASSERT_TRUE(tree.writeBinary(out));
  const std::string bytes = out.str();
  std::unique_ptr<octomap::OcTree> read;
  EXPECT_FALSE(Read(bytes.substr(0, bytes.size() - 1), &read).ok());
  EXPECT_EQ(read, nullptr);
  EXPECT_FALSE(Read(bytes + "xy", &read).ok());
  EXPECT_FALSE(Read(std::string(), &read).ok());
  // Right data, header counting one node too many.
  const std::string data = bytes.substr(bytes.find("data\n") + 5);
  EXPECT_FALSE(Read(Header(std::to_string(tree.size() + 1), "0.1") + data, &read).ok());
  EXPECT_TRUE(Read(Header(std::to_string(tree.size()), "0.1") + data, &read).ok());
}

TEST(ReadOctreeBinary, RejectsImplausibleResolutionsAndOtherTypes) {
  const std::string leaf_root(2, '\0');  // a root without children: one node
  std::unique_ptr<octomap::OcTree> read;
  EXPECT_TRUE(Read(Header("1", "0.1") + leaf_root, &read).ok());
  for (const char* res : {"0", "-0.1", "nan", "inf", "1e-300", "1e300"}) {
    EXPECT_FALSE(Read(Header("1", res) + leaf_root, &read).ok()) << res;
  }
  std::string color = Header("1", "0.1") + leaf_root;
  color.replace(color.find("id OcTree"), 9, "id ColorOcTree");
  EXPECT_FALSE(Read(color, &read).ok());
  EXPECT_FALSE(Read("not a tree at all", &read).ok());
}

// Regression (fuzzing): OcTree::readBinary recursed once per level without a limit; a
// stream of nested inner nodes overflowed the stack or built nodes below depth 16.
TEST(ReadOctreeBinary, RejectsNodesBelowTheTreeDepth) {
  std::string deep;
  for (int level = 0; level < 17; ++level) deep += std::string("\x03\x00", 2);  // child 0 inner
  deep += std::string(2, '\0');
  std::unique_ptr<octomap::OcTree> read;
  EXPECT_FALSE(Read(Header("18", "0.1") + deep, &read).ok());
  std::string million;
  for (int i = 0; i < 1000000; ++i) million += std::string("\x03\x00", 2);
  EXPECT_FALSE(Read(Header("1000001", "0.1") + million, &read).ok());
}

// Regression (fuzzing): every 2 bytes of input can create 8 nodes (~100 bytes of
// memory); the node count is bounded before OctoMap allocates any.
TEST(ReadOctreeBinary, BoundsTheNodeCountBeforeAllocating) {
  // Root with 8 inner children, each with 8 occupied leaves: 1 + 8 + 64 nodes.
  std::string data = std::string("\xff\xff", 2);
  for (int c = 0; c < 8; ++c) data += std::string("\xaa\xaa", 2);
  std::unique_ptr<octomap::OcTree> read;
  ASSERT_TRUE(Read(Header("73", "0.1") + data, &read).ok());
  EXPECT_EQ(read->size(), 73u);
  OctreeReadLimits limits;
  limits.max_nodes = 72;
  EXPECT_FALSE(Read(Header("73", "0.1") + data, &read, limits).ok());
  EXPECT_EQ(read, nullptr);
}

}  // namespace
}  // namespace mbslam
