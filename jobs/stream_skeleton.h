#pragma once
// The path of a particle stream, for cylinders oriented along it (the oriented cylinders Hoetzlein &
// Höllerer 2009 leave as future work). Sphere scan conversion bins a group along the vertical V axis, so
// where a stream runs sideways (the top of an arc, a hose) one ring spans the whole horizontal run. Here a
// connected set of particles (linked within the grouping distance) is binned along its own path instead:
//
//   1. geodesic distance over the links from one end of the set (Dijkstra twice: from the lowest index to
//      the farthest particle, then from that end), so the distance runs along the stream however it bends;
//   2. levels of one link length along that distance, and in each level the connected pieces ("nodes"):
//      a stream has one node per level, a fork several (the seed's grouping, with the level for V);
//   3. branches: chains of nodes, one child each. A fork starts new branches unless all but one of its
//      children are small (a droplet beside the stream), which the branch absorbs.
//
// Every branch becomes one cylinder of the pool (oriented_rings.h). Plain serial code per component, in a
// fixed order: the same bytes whoever runs it.
#include <cstdint>
#include <span>

#include "jobs/grid_links.h"
#include "jobs/particle_spans.h"

namespace rivulet {

struct SkeletonParams {
    float link = 0;                          // grouping distance: particles closer than this are linked
    std::uint32_t min_branch_particles = 8;  // a fork's child below this (with its subtree) is absorbed
    // When not 0, a node of more members than this is thick, and a chain changing between thin and thick
    // nodes starts a new branch there (the hybrid method cuts streams from the blobs they run into).
    std::uint32_t thick_node = 0;
};

// Scratch of one component, every span as long as its member count unless said otherwise.
struct SkeletonScratch {
    std::span<float> dist;
    std::span<std::uint32_t> heap, heap_pos, level, node, order, link_root;
    // Per node (at most one per member).
    std::span<std::uint32_t> node_level, node_size, node_weight, node_parents, node_children, node_first_edge,
        node_branch, node_mode;
    // Links between nodes of consecutive levels: as long as 2 x members; a component with more links is
    // one branch.
    std::span<std::uint32_t> edge_from, edge_to;
};

// One branch: members [begin, begin + count) of the component's member list after the call, sorted by
// level; `levels` levels from `first_level`.
struct BranchRange {
    std::uint32_t begin = 0, count = 0, first_level = 0, levels = 0;
};

// `members`: the component's particles, ascending; `member_pos[i]` is particle i's position in `members`
// for every member (written by the caller). On return `members` is sorted by (branch, level, index),
// `scratch.level` holds each member's level in that order, and branches[0 .. result) describe the
// branches (at most members.size()). `links` joins points closer than params.link.
std::uint32_t stream_skeleton(const LinkGraph& links, const SkeletonParams& params,
                              std::span<std::uint32_t> members, std::span<std::uint32_t> member_pos,
                              const SkeletonScratch& scratch, std::span<BranchRange> branches);

// Components of the links: `parent` (one per point) ends as each point's component root, the lowest index
// of its component.
void link_components(const LinkGraph& links, std::span<std::uint32_t> parent);

}  // namespace rivulet
