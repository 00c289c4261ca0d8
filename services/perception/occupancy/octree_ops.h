#ifndef MBSLAM_SERVICES_PERCEPTION_OCCUPANCY_OCTREE_OPS_H_
#define MBSLAM_SERVICES_PERCEPTION_OCCUPANCY_OCTREE_OPS_H_

// Two faster equivalents of OctoMap operations, used by OccupancyMap:
//
// * ApplyVoxelUpdates: the update step of OcTree::insertPointCloud (each voxel once per
//   scan, occupied before free), giving the same tree node for node, but walking the
//   tree once in depth-first (Morton) order instead of descending from the root for
//   every voxel. A keyframe's rays touch ~40k voxels at 10 cm; this is what keeps the
//   update within its budget (bench/occupancy_bench.cc).
// * WriteOctreeBinary: the bytes OcTree::writeBinary(std::ostream&) writes (maximum
//   likelihood, pruned), computed from a const tree without copying or modifying it.
//
// Both rely only on OctoMap's public node API and binary format (OctoMap 1.9); the
// tests compare them byte for byte with OctoMap's own functions.

#include <octomap/OcTree.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace mbslam {

// Interleaves the bits of a key so that bits 3l, 3l+1, 3l+2 are bit l of key[0],
// key[1], key[2]: the child index at each level, so sorted codes visit the tree in
// depth-first order.
uint64_t OctreeMortonCode(const octomap::OcTreeKey& key);
octomap::OcTreeKey OctreeKeyOfMortonCode(uint64_t code);

// One voxel update for ApplyVoxelUpdates: OctreeMortonCode(key) << 2 | kind, kind 0 a
// miss, 1 a weak hit (an interpolated end point), 2 a hit.
inline uint64_t VoxelUpdate(const octomap::OcTreeKey& key, bool hit) {
  return OctreeMortonCode(key) << 2 | (hit ? 2u : 0u);
}
inline uint64_t WeakHitVoxelUpdate(const octomap::OcTreeKey& key) {
  return OctreeMortonCode(key) << 2 | 1u;
}

// Applies one scan's voxel updates at the finest depth: every voxel listed is updated
// once, with the hit log-odds if any of its entries is a hit, else with
// `weak_hit_log_odds` if any is a weak hit, else with the miss log-odds (OctoMap's
// insertPointCloud semantics, non-lazy: inner nodes are updated and pruned). Without
// weak hits this is exactly the update step of insertPointCloud. Sorts `updates` in
// place. Returns the change in the number of occupied voxels at the finest resolution.
int64_t ApplyVoxelUpdates(octomap::OcTree* tree, std::vector<uint64_t>* updates,
                          float weak_hit_log_odds = 0.0f);

// A new tree with the parameters of `tree` (resolution, hit / miss log-odds, clamping,
// occupancy threshold) holding the nodes of `tree` that overlap the box of finest-level
// keys [min_key, max_key] (inclusive, per axis), with their values; a pruned leaf that
// straddles the box is kept whole. Inner nodes take the maximum of their kept children
// (OctoMap's non-lazy convention). Used to bound the memory of a long-running map: the
// copy costs one walk over the kept part. `num_occupied` (optional): occupied voxels of
// the copy at the finest resolution.
std::unique_ptr<octomap::OcTree> CropOctree(const octomap::OcTree& tree,
                                            const octomap::OcTreeKey& min_key,
                                            const octomap::OcTreeKey& max_key,
                                            int64_t* num_occupied);

// The number of nodes CropOctree(tree, min_key, max_key) would have, without copying.
size_t CountCropNodes(const octomap::OcTree& tree, const octomap::OcTreeKey& min_key,
                      const octomap::OcTreeKey& max_key);

// Appends to `out` exactly what `octomap::OcTree copy(tree); copy.writeBinary(stream)`
// would write.
void WriteOctreeBinary(const octomap::OcTree& tree, std::string* out);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_OCCUPANCY_OCTREE_OPS_H_
