#include "jobs/stream_skeleton.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rivulet {
namespace {

constexpr std::uint32_t kNone = ~0u;

std::uint32_t find_root(std::span<std::uint32_t> parent, std::uint32_t i) {
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

// The root is the lower index, so the result does not depend on the order of the unions.
void unite(std::span<std::uint32_t> parent, std::uint32_t a, std::uint32_t b) {
    a = find_root(parent, a), b = find_root(parent, b);
    if (a < b)
        parent[b] = a;
    else if (b < a)
        parent[a] = b;
}

// Min-heap of member indices keyed by (dist, index); heap_pos[m] is m's slot or kNone.
struct DistanceHeap {
    std::span<const float> dist;
    std::span<std::uint32_t> heap, pos;
    std::uint32_t size = 0;

    bool before(std::uint32_t a, std::uint32_t b) const {
        return dist[a] < dist[b] || (dist[a] == dist[b] && a < b);
    }
    void place(std::uint32_t slot, std::uint32_t m) { heap[slot] = m, pos[m] = slot; }
    void up(std::uint32_t slot) {
        const std::uint32_t m = heap[slot];
        while (slot > 0) {
            const std::uint32_t parent = (slot - 1) / 2;
            if (!before(m, heap[parent])) break;
            place(slot, heap[parent]);
            slot = parent;
        }
        place(slot, m);
    }
    void down(std::uint32_t slot) {
        const std::uint32_t m = heap[slot];
        for (;;) {
            std::uint32_t child = 2 * slot + 1;
            if (child >= size) break;
            if (child + 1 < size && before(heap[child + 1], heap[child])) ++child;
            if (!before(heap[child], m)) break;
            place(slot, heap[child]);
            slot = child;
        }
        place(slot, m);
    }
    void push_or_lower(std::uint32_t m) {
        if (pos[m] == kNone) place(size++, m);
        up(pos[m]);
    }
    std::uint32_t pop() {
        const std::uint32_t top = heap[0];
        pos[top] = kNone;
        if (--size > 0) {
            place(0, heap[size]);
            down(0);
        }
        return top;
    }
};

struct Component {
    const LinkGraph& graph;
    std::span<const std::uint32_t> members, member_pos;

    // visit(member, distance) for the members linked to member m.
    template <class Visit>
    void links(std::uint32_t m, Visit&& visit) const {
        const std::uint32_t i = members[m];
        for (std::uint32_t e = graph.first[i]; e < graph.first[i + 1]; ++e)
            visit(member_pos[graph.to[e]], graph.length[e]);
    }
};

// Geodesic distances over the links from member `source`; returns the farthest member (the lowest of
// equals). Members out of reach (none, when `members` is a component of the links) keep infinity.
std::uint32_t geodesic(const Component& c, std::uint32_t source, const SkeletonScratch& s) {
    const auto n = static_cast<std::uint32_t>(c.members.size());
    std::fill_n(s.dist.begin(), n, std::numeric_limits<float>::infinity());
    std::fill_n(s.heap_pos.begin(), n, kNone);
    DistanceHeap heap{s.dist, s.heap, s.heap_pos};
    s.dist[source] = 0;
    heap.push_or_lower(source);
    std::uint32_t far = source;
    while (heap.size > 0) {
        const std::uint32_t a = heap.pop();
        if (s.dist[a] > s.dist[far] || (s.dist[a] == s.dist[far] && a < far)) far = a;
        c.links(a, [&](std::uint32_t b, float w) {
            const float d = s.dist[a] + w;
            if (d < s.dist[b]) {
                s.dist[b] = d;
                heap.push_or_lower(b);
            }
        });
    }
    return far;
}

// Nodes: the linked pieces of each level, numbered in order of (level, lowest member). Returns the count.
std::uint32_t find_nodes(const Component& c, const SkeletonScratch& s) {
    const auto n = static_cast<std::uint32_t>(c.members.size());
    for (std::uint32_t m = 0; m < n; ++m) s.link_root[m] = m;
    for (std::uint32_t a = 0; a < n; ++a)
        c.links(a, [&](std::uint32_t b, float) {
            if (b > a && s.level[b] == s.level[a]) unite(s.link_root, a, b);
        });
    for (std::uint32_t m = 0; m < n; ++m) s.order[m] = m;
    std::sort(s.order.begin(), s.order.begin() + n, [&](std::uint32_t a, std::uint32_t b) {
        return s.level[a] < s.level[b] || (s.level[a] == s.level[b] && a < b);
    });
    std::fill_n(s.heap_pos.begin(), n, kNone);  // root -> node
    std::uint32_t nodes = 0;
    for (std::uint32_t k = 0; k < n; ++k) {
        const std::uint32_t m = s.order[k], r = find_root(s.link_root, m);
        if (s.heap_pos[r] == kNone) {
            s.heap_pos[r] = nodes;
            s.node_level[nodes] = s.level[m];
            s.node_size[nodes] = 0;
            ++nodes;
        }
        s.node[m] = s.heap_pos[r];
        ++s.node_size[s.node[m]];
    }
    return nodes;
}

// Links from each node to the nodes of the next level, grouped by node; false when they overflow.
bool find_node_links(const Component& c, std::uint32_t nodes, const SkeletonScratch& s) {
    const auto n = static_cast<std::uint32_t>(c.members.size());
    std::sort(s.order.begin(), s.order.begin() + n, [&](std::uint32_t a, std::uint32_t b) {
        return s.node[a] < s.node[b] || (s.node[a] == s.node[b] && a < b);
    });
    std::fill_n(s.node_mode.begin(), nodes, kNone);  // the last node linked to each node
    std::fill_n(s.node_parents.begin(), nodes, 0u);
    std::fill_n(s.node_children.begin(), nodes, 0u);
    std::uint32_t edges = 0;
    bool fits = true;
    for (std::uint32_t k = 0; k < n && fits; ++k) {
        const std::uint32_t a = s.order[k], from = s.node[a];
        if (k == 0 || s.node[s.order[k - 1]] != from) s.node_first_edge[from] = edges;
        c.links(a, [&](std::uint32_t b, float) {
            const std::uint32_t to = s.node[b];
            if (s.level[b] != s.level[a] + 1 || s.node_mode[to] == from || !fits) return;
            if (edges == s.edge_to.size()) {
                fits = false;
                return;
            }
            s.node_mode[to] = from;
            s.edge_from[edges] = from, s.edge_to[edges] = to;
            ++edges, ++s.node_children[from], ++s.node_parents[to];
        });
    }
    return fits;
}

enum Mode : std::uint32_t { kStart = 0, kContinue = 1, kAbsorb = 2 };

std::uint32_t assign_branches(std::uint32_t nodes, const SkeletonParams& params, const SkeletonScratch& s) {
    for (std::uint32_t a = nodes; a-- > 0;) {
        std::uint64_t w = s.node_size[a];
        for (std::uint32_t e = 0; e < s.node_children[a]; ++e)
            w += s.node_weight[s.edge_to[s.node_first_edge[a] + e]];
        s.node_weight[a] = static_cast<std::uint32_t>(std::min<std::uint64_t>(w, ~0u));
    }
    std::fill_n(s.node_branch.begin(), nodes, kNone);
    std::fill_n(s.node_mode.begin(), nodes, std::uint32_t{kStart});
    const auto thick = [&](std::uint32_t node) {
        return params.thick_node > 0 && s.node_size[node] > params.thick_node;
    };
    std::uint32_t branches = 0;
    for (std::uint32_t a = 0; a < nodes; ++a) {
        if (s.node_branch[a] == kNone) s.node_branch[a] = branches++, s.node_mode[a] = kStart;
        const std::uint32_t branch = s.node_branch[a];
        const std::span<const std::uint32_t> children =
            s.edge_to.subspan(s.node_first_edge[a], s.node_children[a]);
        // A fork keeps its heavy children apart; a node whose children are all small keeps the heaviest.
        std::uint32_t heavy = 0, heaviest = kNone;
        for (const std::uint32_t c : children) {
            heavy += s.node_weight[c] >= params.min_branch_particles;
            if (heaviest == kNone || s.node_weight[c] > s.node_weight[heaviest]) heaviest = c;
        }
        for (const std::uint32_t c : children) {
            if (s.node_branch[c] != kNone) continue;  // a merge: its first parent decided
            const bool significant =
                heavy > 0 ? s.node_weight[c] >= params.min_branch_particles : c == heaviest;
            if (s.node_mode[a] == kAbsorb || !significant) {
                s.node_branch[c] = branch, s.node_mode[c] = kAbsorb;
            } else if (heavy <= 1 && s.node_parents[c] == 1 && thick(a) == thick(c)) {
                s.node_branch[c] = branch, s.node_mode[c] = kContinue;
            }
        }
    }
    return branches;
}

}  // namespace

void link_components(const LinkGraph& links, std::span<std::uint32_t> parent) {
    const auto n = static_cast<std::uint32_t>(links.first.size() - 1);
    for (std::uint32_t i = 0; i < n; ++i) parent[i] = i;
    for (std::uint32_t i = 0; i < n; ++i)
        for (std::uint32_t e = links.first[i]; e < links.first[i + 1]; ++e)
            if (links.to[e] > i) unite(parent, i, links.to[e]);
    for (std::uint32_t i = 0; i < n; ++i) parent[i] = find_root(parent, i);
}

std::uint32_t stream_skeleton(const LinkGraph& graph, const SkeletonParams& params,
                              std::span<std::uint32_t> members, std::span<std::uint32_t> member_pos,
                              const SkeletonScratch& s, std::span<BranchRange> branches) {
    const auto n = static_cast<std::uint32_t>(members.size());
    if (n == 0) return 0;
    const Component c{graph, members, member_pos};
    const std::uint32_t end = geodesic(c, 0, s);
    geodesic(c, end, s);
    float top = 0;
    for (std::uint32_t m = 0; m < n; ++m)
        if (std::isfinite(s.dist[m])) top = std::max(top, s.dist[m]);
    const auto last_level = static_cast<std::uint32_t>(top / params.link);
    for (std::uint32_t m = 0; m < n; ++m)
        s.level[m] =
            std::isfinite(s.dist[m]) ? static_cast<std::uint32_t>(s.dist[m] / params.link) : last_level;

    const std::uint32_t nodes = find_nodes(c, s);
    if (find_node_links(c, nodes, s)) {
        assign_branches(nodes, params, s);
    } else {
        std::fill_n(s.node_branch.begin(), nodes, 0u);  // too tangled to follow: one branch
    }

    for (std::uint32_t m = 0; m < n; ++m) s.order[m] = m;
    const auto branch_of = [&](std::uint32_t m) { return s.node_branch[s.node[m]]; };
    std::sort(s.order.begin(), s.order.begin() + n, [&](std::uint32_t a, std::uint32_t b) {
        if (branch_of(a) != branch_of(b)) return branch_of(a) < branch_of(b);
        if (s.level[a] != s.level[b]) return s.level[a] < s.level[b];
        return a < b;
    });
    // Apply the order to members and levels through the heap arrays (free by now).
    for (std::uint32_t k = 0; k < n; ++k) {
        s.heap[k] = members[s.order[k]];
        s.heap_pos[k] = s.level[s.order[k]];
        s.node_size[k] = branch_of(s.order[k]);  // node sizes are no longer needed
    }
    std::copy_n(s.heap.begin(), n, members.begin());
    std::copy_n(s.heap_pos.begin(), n, s.level.begin());
    std::uint32_t out = 0;
    for (std::uint32_t k = 0; k < n; ++k) {
        if (k == 0 || s.node_size[k] != s.node_size[k - 1]) branches[out++] = {k, 0, s.level[k], 0};
        BranchRange& b = branches[out - 1];
        ++b.count;
        b.levels = s.level[k] - b.first_level + 1;
    }
    return out;
}

}  // namespace rivulet
