#include "systems/scan/scan_mesh.h"

#include "jobs/low_res_sphere.h"
#include "jobs/mesh_hash.h"

namespace rivulet {

TriangleMesh assemble_scan_mesh(const ScanOutput& out, const CylinderLayout& layout, float radius) {
    TriangleMesh mesh;
    assemble_scan_mesh(out, layout, radius, mesh);
    return mesh;
}

void assemble_scan_mesh(const ScanOutput& out, const CylinderLayout& layout, float radius,
                        TriangleMesh& mesh) {
    mesh.vertices.clear();
    mesh.indices.clear();
    const std::uint32_t u = layout.u;
    const std::size_t vpc = layout.verts_per_cylinder();
    for (const GroupDraw& d : out.draws.span(out.draw_count)) {
        const float* src = out.vertices.data() + d.cylinder * vpc * 6;
        const auto base = static_cast<std::uint32_t>(mesh.vertex_count());
        const std::uint32_t rings = d.vmax - d.vmin + 1;
        auto copy_vertex = [&](std::uint32_t v) {
            mesh.vertices.insert(mesh.vertices.end(), src + 6 * v, src + 6 * v + 6);
        };
        for (std::uint32_t r = d.vmin; r <= d.vmax; ++r)
            for (std::uint32_t k = 0; k < u; ++k) copy_vertex(layout.side_vertex(r, k));
        copy_vertex(layout.top_pole(d.vmin));
        copy_vertex(layout.bottom_pole(d.vmax));
        const std::uint32_t top = base + rings * u, bottom = top + 1;
        auto side = [&](std::uint32_t r, std::uint32_t k) { return base + (r - d.vmin) * u + k % u; };
        auto tri = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
            mesh.indices.insert(mesh.indices.end(), {a, b, c});
        };
        // Same triangles and winding as write_cylinder_indices, renumbered.
        for (std::uint32_t b = d.vmin; b < d.vmax; ++b) {
            for (std::uint32_t k = 0; k < u; ++k) {
                tri(side(b, k), side(b + 1, k + 1), side(b + 1, k));
                tri(side(b, k), side(b, k + 1), side(b + 1, k + 1));
            }
        }
        for (std::uint32_t k = 0; k < u; ++k) {
            tri(top, side(d.vmin, k + 1), side(d.vmin, k));
            tri(bottom, side(d.vmax, k), side(d.vmax, k + 1));
        }
    }
    const SphereTemplate& sphere = low_res_sphere();
    const std::size_t sv = sphere.positions.size() / 3;
    for (std::uint32_t s = 0; s < out.sphere_count; ++s) {
        const float* c = out.sphere_centers.data() + 3 * s;
        const auto base = static_cast<std::uint32_t>(mesh.vertex_count());
        for (std::size_t i = 0; i < sv; ++i) {
            const float* n = sphere.positions.data() + 3 * i;
            mesh.vertices.insert(mesh.vertices.end(), {c[0] + radius * n[0], c[1] + radius * n[1],
                                                       c[2] + radius * n[2], n[0], n[1], n[2]});
        }
        for (std::uint32_t i : sphere.indices) mesh.indices.push_back(base + i);
    }
}

std::uint64_t mesh_hash(const TriangleMesh& mesh) {
    return mesh_hash(TriangleMeshView{mesh.vertices, mesh.indices});
}

std::uint64_t mesh_hash(const TriangleMeshView& mesh) {
    Hasher h;
    h.add(mesh.vertices);
    h.add(mesh.indices);
    return h.digest();
}

std::uint64_t frame_output_hash(const ScanOutput& out, const CylinderLayout& layout) {
    Hasher h;
    const std::size_t vpc = layout.verts_per_cylinder();
    for (const GroupDraw& d : out.draws.span(out.draw_count)) {
        h.add(&d, sizeof d);
        const std::size_t first = d.cylinder * vpc + layout.ring_first_vertex(d.vmin);
        const std::size_t last = d.cylinder * vpc + layout.ring_first_vertex(d.vmax + 1);
        h.add(out.vertices.data() + first * 6, (last - first) * 6 * sizeof(float));
    }
    h.add(out.sphere_view());
    return h.digest();
}

}  // namespace rivulet
