#include "systems/scan/oriented_scan.h"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "jobs/cell_radix_sort.h"
#include "jobs/cylinder_normals.h"
#include "jobs/grid_links.h"
#include "jobs/isolated_particles.h"
#include "jobs/oriented_rings.h"

namespace rivulet {
namespace {
constexpr std::uint32_t kNoBranch = ~0u;
}  // namespace

OrientedScan::OrientedScan(const ScanSettings& settings, std::size_t max_particles)
    : settings_(settings), max_particles_(max_particles) {
    if (const std::string err = settings.validate(); !err.empty()) throw std::invalid_argument(err);
    if (max_particles == 0 || max_particles > (std::size_t(1) << 30))
        throw std::invalid_argument("particle capacity must be in [1, 2^30], got " +
                                    std::to_string(max_particles));
    layout_ = {settings.u, settings.v};
    const double bytes = 4.0 * (40.0 * double(max_particles) +
                                6.0 * double(settings.max_groups) * layout_.verts_per_cylinder());
    if (bytes > double(std::uint64_t{4} << 30))
        throw std::invalid_argument(fmt::format(
            "oriented scan conversion buffers for --max-groups {}, --u {}, --v {} and {} particles would "
            "take {:.1f} GiB (limit 4 GiB): lower them",
            settings.max_groups, settings.u, settings.v, max_particles, bytes / double(1 << 30)));
    cos_t_.reserve(settings.u), sin_t_.reserve(settings.u);
    fill_angle_table(cos_t_.span(settings.u), sin_t_.span(settings.u));
    const std::size_t n = max_particles;
    order_tmp_.reserve(n), counts_.reserve(kCellSortDigits);
    cell_key_.reserve(n), key_tmp_.reserve(n), bead_key_.reserve(n), by_cell_.reserve(n),
        bead_first_.reserve(n + 1), link_first_.reserve(n + 1);
    pair_a_.reserve(4 * n), pair_b_.reserve(4 * n), pair_length_.reserve(4 * n);
    link_to_.reserve(8 * n), link_length_.reserve(8 * n);
    bead_x_.reserve(n), bead_y_.reserve(n), bead_z_.reserve(n);
    particle_at_.reserve(n + 1), branch_particles_.reserve(n), branch_levels_.reserve(n);
    for (auto* a :
         {&root_,      &members_,      &member_pos_,   &component_first_, &component_end_,   &heap_,
          &heap_pos_,  &level_,        &node_,         &sort_order_,      &link_root_,       &node_level_,
          &node_size_, &node_weight_,  &node_parents_, &node_children_,   &node_first_edge_, &node_branch_,
          &node_mode_, &branch_counts_})
        a->reserve(n);
    dist_.reserve(n);
    edge_from_.reserve(2 * n), edge_to_.reserve(2 * n);
    branch_ranges_.reserve(n);
    drawn_component_.reserve(settings.max_groups), drawn_branch_.reserve(settings.max_groups);
    tube_.reserve(settings.max_groups), stream_.reserve(settings.max_groups);
    bead_drawn_.reserve(n), bead_blob_.reserve(n);
    draw_first_.reserve(settings.max_groups), draw_last_.reserve(settings.max_groups);
    ring_x_.reserve(settings.v), ring_y_.reserve(settings.v), ring_z_.reserve(settings.v),
        ring_r_.reserve(settings.v);
    // A branch's path has its levels + 2 points (levels <= members) and its level table levels + 1.
    const std::size_t path = n + 2 * std::size_t(settings.max_groups);
    path_x_.reserve(path), path_y_.reserve(path), path_z_.reserve(path), arc_.reserve(path);
    level_start_.reserve(n + settings.max_groups);
    circle_x_.reserve(kMaxRingsPerSphere * n), circle_z_.reserve(kMaxRingsPerSphere * n),
        circle_rho_.reserve(kMaxRingsPerSphere * n);
    cut_first_.reserve(n), cut_count_.reserve(n);
    ring_first_.reserve(std::size_t(settings.max_groups) * (settings.v + 1)),
        ring_cursor_.reserve(std::size_t(settings.max_groups) * settings.v);
    frames_.reserve(std::size_t(settings.max_groups) * kFrameFloats * settings.v);
    planes_.reserve(std::size_t(settings.max_groups) * 4 * (settings.v + kPlanePadding));
    member_x_.reserve(n), member_y_.reserve(n), member_z_.reserve(n);
    grouped_.reserve(n);
}

void OrientedScan::prepare_output(ScanOutput& out) const {
    out.vertices.reserve(std::size_t(settings_.max_groups) * layout_.verts_per_cylinder() * 6);
    out.draws.reserve(settings_.max_groups);
    out.sphere_centers.reserve(max_particles_ * 3);
}

float OrientedScan::bead_link() const {
    return kBeadLink * settings_.grouping_distance();
}

LinkGraph OrientedScan::link_graph() const {
    const std::size_t links = link_first_[beads_];
    return {link_first_.span(beads_ + 1), link_to_.span(links), link_length_.span(links)};
}

ConstPositions OrientedScan::bead_positions() const {
    return {bead_x_.span(beads_), bead_y_.span(beads_), bead_z_.span(beads_)};
}

void OrientedScan::link(ConstPositions p) {
    if (p.size() > max_particles_)
        throw std::length_error("scan conversion capacity " + std::to_string(max_particles_) +
                                " exceeded by " + std::to_string(p.size()) + " particles");
    particles_ = p.size();
    components_ = 0, drawn_ = 0, undrawn_ = 0, beads_ = 0;
    if (particles_ == 0) return;
    const auto n = static_cast<std::uint32_t>(particles_);
    const float link = bead_link(), cell = kBeadCell * settings_.grouping_distance();
    float lo[3] = {p.x[0], p.y[0], p.z[0]}, hi[3] = {lo[0], lo[1], lo[2]};
    for (std::uint32_t i = 0; i < n; ++i) {
        lo[0] = std::min(lo[0], p.x[i]), lo[1] = std::min(lo[1], p.y[i]), lo[2] = std::min(lo[2], p.z[i]);
        hi[0] = std::max(hi[0], p.x[i]), hi[1] = std::max(hi[1], p.y[i]), hi[2] = std::max(hi[2], p.z[i]);
    }
    for (int a = 0; a < 3; ++a)
        if (!(double(hi[a]) - double(lo[a]) < double(cell) * (1 << 20)))
            throw std::invalid_argument(fmt::format(
                "particles span {:.0f} grouping distances along an axis (or are not finite): raise --epsilon",
                (double(hi[a]) - double(lo[a])) / link));

    // Beads: particles sorted by (cell, index) (jobs/cell_radix_sort.h); each cell's particles at their
    // centroid, so the beads come in cell order.
    const float inv = 1.0f / cell;
    const auto index = [&](float v, int axis) {
        return static_cast<std::uint32_t>((v - lo[axis]) * inv) + kLinkReach;
    };
    for (std::uint32_t i = 0; i < n; ++i)
        cell_key_[i] = pack_cell_key(index(p.x[i], 0), index(p.y[i], 1), index(p.z[i], 2));
    cell_radix_sort({cell_key_.span(n), key_tmp_.span(n), by_cell_.span(n), order_tmp_.span(n),
                     counts_.span(kCellSortDigits)},
                    index(hi[0], 0), index(hi[1], 1), index(hi[2], 2));
    for (std::uint32_t k = 0; k < n; ++k) {
        const std::uint32_t i = by_cell_[k];
        if (k == 0 || cell_key_[k] != cell_key_[k - 1]) {
            if (beads_ > 0) {
                const float inv_count = 1.0f / static_cast<float>(k - bead_first_[beads_ - 1]);
                bead_x_[beads_ - 1] *= inv_count, bead_y_[beads_ - 1] *= inv_count,
                    bead_z_[beads_ - 1] *= inv_count;
            }
            bead_first_[beads_] = k;
            bead_key_[beads_] = cell_key_[k];
            bead_x_[beads_] = bead_y_[beads_] = bead_z_[beads_] = 0;
            ++beads_;
        }
        bead_x_[beads_ - 1] += p.x[i], bead_y_[beads_ - 1] += p.y[i], bead_z_[beads_ - 1] += p.z[i];
    }
    const float inv_last = 1.0f / static_cast<float>(n - bead_first_[beads_ - 1]);
    bead_x_[beads_ - 1] *= inv_last, bead_y_[beads_ - 1] *= inv_last, bead_z_[beads_ - 1] *= inv_last;
    bead_first_[beads_] = n;

    // The beads' links; the pair buffers grow rarely (a frame far denser than any before).
    const auto pairs = [&] {
        return grid_link_pairs(bead_positions(), bead_key_.span(beads_), kLinkReach, link,
                               pair_a_.span(pair_a_.capacity()), pair_b_.span(pair_b_.capacity()),
                               pair_length_.span(pair_length_.capacity()));
    };
    std::size_t links = pairs();
    if (links > pair_a_.capacity()) {
        for (auto* a : {&pair_a_, &pair_b_}) a->reserve(links + links / 2);
        pair_length_.reserve(links + links / 2);
        link_to_.reserve(2 * (links + links / 2)), link_length_.reserve(2 * (links + links / 2));
        pairs();
    }
    link_rows(pair_a_.span(links), pair_b_.span(links), pair_length_.span(links),
              link_first_.span(beads_ + 1), link_to_.span(2 * links), link_length_.span(2 * links));
    link_components(link_graph(), root_.span(beads_));

    // Beads grouped by component (in order of their lowest bead), ascending within. A component of one
    // bead of one particle is an isolated sphere.
    const std::span<std::uint32_t> cursor = heap_.span(beads_);  // per root: size, then cursor
    std::fill(cursor.begin(), cursor.end(), 0u);
    for (std::uint32_t i = 0; i < beads_; ++i) ++cursor[root_[i]];
    std::uint32_t next = 0;
    for (std::uint32_t i = 0; i < beads_; ++i) {
        if (root_[i] != i) continue;
        const std::uint32_t size = cursor[i];
        cursor[i] = next;
        if (size >= 2 || bead_first_[i + 1] - bead_first_[i] >= 2) {
            component_first_[components_] = next;
            component_end_[components_] = next + size;
            ++components_;
        }
        next += size;
    }
    for (std::uint32_t i = 0; i < beads_; ++i) members_[cursor[root_[i]]++] = i;
}

SkeletonScratch OrientedScan::scratch(std::uint32_t c) {
    const std::size_t first = component_first_[c], count = component_end_[c] - first;
    auto at = [&](AlignedArray<std::uint32_t>& a) { return a.span(max_particles_).subspan(first, count); };
    return {dist_.span(max_particles_).subspan(first, count),
            at(heap_),
            at(heap_pos_),
            at(level_),
            at(node_),
            at(sort_order_),
            at(link_root_),
            at(node_level_),
            at(node_size_),
            at(node_weight_),
            at(node_parents_),
            at(node_children_),
            at(node_first_edge_),
            at(node_branch_),
            at(node_mode_),
            edge_from_.span(2 * max_particles_).subspan(2 * first, 2 * count),
            edge_to_.span(2 * max_particles_).subspan(2 * first, 2 * count)};
}

void OrientedScan::skeleton(ConstPositions, std::uint32_t c) {
    const std::uint32_t first = component_first_[c], count = component_end_[c] - first;
    const std::span<std::uint32_t> members = members_.span(max_particles_).subspan(first, count);
    for (std::uint32_t k = 0; k < count; ++k) member_pos_[members[k]] = k;
    const SkeletonParams params{bead_link(), kMinBranchBeads, thick_node_beads_};
    branch_counts_[c] = stream_skeleton(link_graph(), params, members, member_pos_.span(beads_), scratch(c),
                                        branch_ranges_.span(max_particles_).subspan(first, count));
}

void OrientedScan::cylinders() {
    drawn_ = 0, undrawn_ = 0;
    for (std::uint32_t c = 0; c < components_; ++c)
        for (std::uint32_t b = 0; b < branch_counts_[c]; ++b) {
            if (drawn_ == settings_.max_groups) {
                ++undrawn_;
                continue;
            }
            drawn_component_[drawn_] = c, drawn_branch_[drawn_] = b;
            ++drawn_;
        }
    std::fill_n(bead_drawn_.data(), beads_, kNoBranch);
    for (std::uint32_t d = 0; d < drawn_; ++d) {
        const std::uint32_t first = component_first_[drawn_component_[d]] + drawn_range(d).begin;
        for (std::uint32_t m = first; m < first + drawn_range(d).count; ++m) bead_drawn_[members_[m]] = d;
    }
    // Where each member bead's particles go in the drawn branches' particle lists.
    std::uint32_t at = 0;
    for (std::uint32_t c = 0; c < components_; ++c)
        for (std::uint32_t m = component_first_[c]; m < component_end_[c]; ++m) {
            particle_at_[m] = at;
            at += bead_first_[members_[m] + 1] - bead_first_[members_[m]];
        }
}

const BranchRange& OrientedScan::drawn_range(std::uint32_t d) const {
    return branch_ranges_[component_first_[drawn_component_[d]] + drawn_branch_[d]];
}

std::span<const std::uint32_t> OrientedScan::branch_particles(std::uint32_t d) const {
    const BranchRange& r = drawn_range(d);
    const std::uint32_t first = component_first_[drawn_component_[d]] + r.begin;
    const std::uint32_t end = first + r.count;
    const std::uint32_t from = particle_at_[first];
    const std::uint32_t to =
        particle_at_[end - 1] + bead_first_[members_[end - 1] + 1] - bead_first_[members_[end - 1]];
    return branch_particles_.span(max_particles_).subspan(from, to - from);
}

void OrientedScan::rings(ConstPositions p, std::uint32_t d, ScanOutput& out) {
    const BranchRange& r = drawn_range(d);
    const std::uint32_t first = component_first_[drawn_component_[d]] + r.begin;
    // The branch's particles in the order of its beads, so by level.
    const std::uint32_t from = particle_at_[first];
    std::uint32_t count = 0;
    for (std::uint32_t m = first; m < first + r.count; ++m) {
        const std::uint32_t bead = members_[m];
        for (std::uint32_t k = bead_first_[bead]; k < bead_first_[bead + 1]; ++k, ++count) {
            branch_particles_[from + count] = by_cell_[k];
            branch_levels_[from + count] = level_[m];
        }
    }
    const std::size_t path_at = first + 2 * std::size_t(d), table_at = first + d;
    const std::size_t cuts_at = kMaxRingsPerSphere * std::size_t(from), cuts = kMaxRingsPerSphere * count;
    const RingScratch scratch{
        path_x_.span(path_x_.capacity()).subspan(path_at, r.levels + 2),
        path_y_.span(path_y_.capacity()).subspan(path_at, r.levels + 2),
        path_z_.span(path_z_.capacity()).subspan(path_at, r.levels + 2),
        arc_.span(arc_.capacity()).subspan(path_at, r.levels + 2),
        member_x_.span(max_particles_).subspan(from, count),
        member_y_.span(max_particles_).subspan(from, count),
        member_z_.span(max_particles_).subspan(from, count),
        circle_x_.span(circle_x_.capacity()).subspan(cuts_at, cuts),
        circle_z_.span(circle_z_.capacity()).subspan(cuts_at, cuts),
        circle_rho_.span(circle_rho_.capacity()).subspan(cuts_at, cuts),
        level_start_.span(level_start_.capacity()).subspan(table_at, r.levels + 1),
        cut_first_.span(max_particles_).subspan(from, count),
        ring_first_.span(ring_first_.capacity()).subspan(d * (layout_.v + 1), layout_.v + 1),
        ring_cursor_.span(ring_cursor_.capacity()).subspan(d * layout_.v, layout_.v),
        cut_count_.span(max_particles_).subspan(from, count),
        frames_.span(frames_.capacity()).subspan(d * kFrameFloats * layout_.v, kFrameFloats * layout_.v),
        planes_.span(planes_.capacity())
            .subspan(d * 4 * (layout_.v + kPlanePadding), 4 * (layout_.v + kPlanePadding))};
    const OrientedRingParams params{layout_,           settings_.radius,
                                    bead_link(),       settings_.radius,
                                    settings_.section, {cos_t_.span(layout_.u), sin_t_.span(layout_.u)}};
    const std::size_t vpc = std::size_t(layout_.verts_per_cylinder()) * 6;
    stream_[d] = 1;
    draw_first_[d] = 0;
    tube_[d] =
        oriented_rings(p, branch_particles_.span(max_particles_).subspan(from, count),
                       branch_levels_.span(max_particles_).subspan(from, count), r.first_level, r.levels,
                       params, scratch, out.vertices.span(out.vertices.capacity()).subspan(d * vpc, vpc));
    draw_last_[d] = tube_[d].rings - 1;
}

void OrientedScan::normals(std::uint32_t d, ScanOutput& out) {
    const std::size_t vpc = std::size_t(layout_.verts_per_cylinder()) * 6;
    if (!stream_[d]) return;
    const std::uint32_t first = draw_first_[d], last = draw_last_[d];
    cylinder_normals(layout_, first, last, first, last,
                     out.vertices.span(out.vertices.capacity()).subspan(d * vpc, vpc));
}

void OrientedScan::isolated(ConstPositions p, ScanOutput& out) {
    const std::span<std::uint8_t> grouped = grouped_.span(particles_);
    std::fill(grouped.begin(), grouped.end(), std::uint8_t{0});
    for (std::uint32_t d = 0; d < drawn_; ++d)
        for (const std::uint32_t i : branch_particles(d)) grouped[i] = 1;
    out.sphere_count = collect_isolated(p, grouped, out.sphere_centers.span(particles_ * 3));
}

void OrientedScan::stage(ScanOutput& out) {
    std::uint64_t triangles = 0;
    std::uint32_t draws = 0;
    for (std::uint32_t d = 0; d < drawn_; ++d) {
        if (!stream_[d]) continue;
        out.draws[draws++] = {d, draw_first_[d], draw_last_[d]};
        triangles += 2ull * layout_.u * (draw_last_[d] - draw_first_[d]) + 2ull * layout_.u;
    }
    out.draw_count = draws;
    out.bin_entries = static_cast<std::uint32_t>(particles_);
    out.pool_exhausted = undrawn_;
    out.triangles = triangles;
}

void OrientedScan::split_streams(ConstPositions p, float max_radius, float min_aspect, ScanOutput& out,
                                 std::span<std::uint8_t> to_slices) {
    std::fill(to_slices.begin(), to_slices.begin() + std::ptrdiff_t(particles_), std::uint8_t{0});
    const std::size_t vpc = std::size_t(layout_.verts_per_cylinder()) * 6;
    for (std::uint32_t d = 0; d < drawn_; ++d) {
        // Each ring's centre (its vertices' mean) and mean radius.
        const float* v = out.vertices.data() + d * vpc;
        const std::uint32_t rings = tube_[d].rings;
        for (std::uint32_t r = 0; r < rings; ++r) {
            const Vec3f c = ring_centre(v, r);
            float sum = 0;
            for (std::uint32_t k = 0; k < layout_.u; ++k) {
                const float* q = v + 6 * std::size_t(layout_.side_vertex(r, k));
                sum += length(Vec3f{q[0], q[1], q[2]} - c);
            }
            ring_x_[r] = c.x, ring_y_[r] = c.y, ring_z_[r] = c.z;
            ring_r_[r] = sum / static_cast<float>(layout_.u);
        }
        // The longest run of thin rings is the stream; it is drawn if long enough for its width.
        std::uint32_t best = 0, best_first = 0;
        for (std::uint32_t r = 0; r < rings;) {
            if (ring_r_[r] > max_radius) {
                ++r;
                continue;
            }
            std::uint32_t e = r;
            while (e < rings && ring_r_[e] <= max_radius) ++e;
            if (e - r > best) best = e - r, best_first = r;
            r = e;
        }
        float widest = 0;
        for (std::uint32_t r = best_first; r < best_first + best; ++r) widest = std::max(widest, ring_r_[r]);
        const float run_length = rings > 1 ? tube_[d].length * static_cast<float>(best > 0 ? best - 1 : 0) /
                                                 static_cast<float>(rings - 1)
                                           : 0.0f;
        stream_[d] = best >= 2 && run_length >= min_aspect * widest;
        draw_first_[d] = best_first, draw_last_[d] = best_first + (best > 0 ? best - 1 : 0);
        // Particles nearest a ring outside the run (or of a blob) go to marching slices.
        for (const std::uint32_t i : branch_particles(d)) {
            if (!stream_[d]) {
                to_slices[i] = 1;
                continue;
            }
            std::uint32_t nearest = 0;
            float nearest_d2 = std::numeric_limits<float>::infinity();
            for (std::uint32_t r = 0; r < rings; ++r) {
                const float ex = p.x[i] - ring_x_[r], ey = p.y[i] - ring_y_[r], ez = p.z[i] - ring_z_[r];
                const float d2 = ex * ex + ey * ey + ez * ez;
                if (d2 < nearest_d2) nearest_d2 = d2, nearest = r;
            }
            if (nearest < draw_first_[d] || nearest > draw_last_[d]) to_slices[i] = 1;
        }
    }
    // The seam: a stream's beads linked to a bead with particles in slices go there too.
    for (std::uint32_t b = 0; b < beads_; ++b) {
        bead_blob_[b] = 0;
        for (std::uint32_t k = bead_first_[b]; k < bead_first_[b + 1]; ++k)
            bead_blob_[b] |= to_slices[by_cell_[k]];
    }
    const LinkGraph links = link_graph();
    for (std::uint32_t b = 0; b < beads_; ++b) {
        if (bead_blob_[b] || bead_drawn_[b] == kNoBranch || !stream_[bead_drawn_[b]]) continue;
        bool near = false;
        for (std::uint32_t e = links.first[b]; e < links.first[b + 1]; ++e)
            near = near || bead_blob_[links.to[e]];
        if (near)
            for (std::uint32_t k = bead_first_[b]; k < bead_first_[b + 1]; ++k) to_slices[by_cell_[k]] = 1;
    }
    // A stream wholly within a blob's reach (a short tail, a droplet touching it) is the blob's.
    for (std::uint32_t d = 0; d < drawn_; ++d) {
        if (!stream_[d]) continue;
        bool inside = true;
        for (const std::uint32_t i : branch_particles(d)) inside = inside && to_slices[i] == 1;
        if (inside) stream_[d] = 0;
        if (stream_[d]) taper_seams(p, d, to_slices, out);
    }
}

// A drawn end of a stream whose nearest particles went to marching slices ends inside the blob's
// surface: its end ring and the one before it shrink towards their centres and the end's pole goes to
// the ring's centre, so the tube, not as wide as the blob's surface around the same particles there,
// stays beneath it.
void OrientedScan::taper_seams(ConstPositions p, std::uint32_t d, std::span<const std::uint8_t> to_slices,
                               ScanOutput& out) {
    const std::size_t vpc = std::size_t(layout_.verts_per_cylinder()) * 6;
    float* v = out.vertices.data() + d * vpc;
    const std::uint32_t ends[2] = {draw_first_[d], draw_last_[d]};
    for (int e = 0; e < 2; ++e) {
        const std::uint32_t ring = ends[e];
        const Vec3f c = ring_centre(v, ring);
        // The end is a seam when the particle nearest its ring's centre is meshed by slices.
        float best = std::numeric_limits<float>::infinity();
        bool seam = false;
        for (const std::uint32_t i : branch_particles(d)) {
            const Vec3f q{p.x[i] - c.x, p.y[i] - c.y, p.z[i] - c.z};
            if (dot(q, q) < best) best = dot(q, q), seam = to_slices[i] == 1;
        }
        if (!seam) continue;
        const std::uint32_t inner = e == 0 ? ring + 1 : ring - 1;
        scale_ring(v, ring, kSeamEndScale);
        if (draw_last_[d] > draw_first_[d]) scale_ring(v, inner, kSeamInnerScale);
        float* pole = v + 6 * std::size_t(e == 0 ? layout_.top_pole(ring) : layout_.bottom_pole(ring));
        pole[0] = c.x, pole[1] = c.y, pole[2] = c.z;
    }
}

void OrientedScan::scale_ring(float* v, std::uint32_t ring, float scale) const {
    const Vec3f c = ring_centre(v, ring);
    for (std::uint32_t k = 0; k < layout_.u; ++k) {
        float* q = v + 6 * std::size_t(layout_.side_vertex(ring, k));
        q[0] = c.x + scale * (q[0] - c.x), q[1] = c.y + scale * (q[1] - c.y),
        q[2] = c.z + scale * (q[2] - c.z);
    }
}

Vec3f OrientedScan::ring_centre(const float* v, std::uint32_t ring) const {
    Vec3f c{};
    for (std::uint32_t k = 0; k < layout_.u; ++k) {
        const float* q = v + 6 * std::size_t(layout_.side_vertex(ring, k));
        c = c + Vec3f{q[0], q[1], q[2]};
    }
    return c * (1.0f / static_cast<float>(layout_.u));
}

void OrientedScan::extract_serial(ConstPositions p, ScanOutput& out) {
    link(p);
    for (std::uint32_t c = 0; c < components_; ++c) skeleton(p, c);
    cylinders();
    for (std::uint32_t d = 0; d < drawn_; ++d) rings(p, d, out);
    for (std::uint32_t d = 0; d < drawn_; ++d) normals(d, out);
    isolated(p, out);
    stage(out);
}

}  // namespace rivulet
