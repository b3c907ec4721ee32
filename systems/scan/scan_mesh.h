#pragma once
// Turning a frame's scan-conversion output into one indexed triangle mesh (for `rivulet mesh`, tests and
// exports), and hashing it. Not part of the per-frame graph: assembling allocates.
#include <cstdint>
#include <vector>

#include "jobs/cylinder_layout.h"
#include "systems/render/frame_view.h"
#include "systems/scan/scan_output.h"

namespace rivulet {

struct TriangleMesh {
    std::vector<float> vertices;         // 6 floats per vertex: position, normal
    std::vector<std::uint32_t> indices;  // triangles, counter-clockwise from outside
    std::size_t vertex_count() const { return vertices.size() / 6; }
    std::size_t triangle_count() const { return indices.size() / 3; }
};

// Each drawn cylinder in group order (its side vertices of rings [vmin, vmax] and its two end poles,
// closed by the caps), then one low-resolution sphere per isolated particle of radius `radius`.
TriangleMesh assemble_scan_mesh(const ScanOutput& out, const CylinderLayout& layout, float radius);
// The same into `mesh`, whose buffers are reused (no allocation once they are large enough).
void assemble_scan_mesh(const ScanOutput& out, const CylinderLayout& layout, float radius,
                        TriangleMesh& mesh);

// mesh_hash: XXH3-64 of the vertex buffer bytes followed by the index buffer bytes.
std::uint64_t mesh_hash(const TriangleMesh& mesh);
std::uint64_t mesh_hash(const TriangleMeshView& mesh);  // the same bytes, from views (frame slots)

// A frame's hash without assembling: draw list, every drawn ring range of the vertex pool, sphere centres.
// Identical outputs give identical hashes; cheap enough to run every frame.
std::uint64_t frame_output_hash(const ScanOutput& out, const CylinderLayout& layout);

}  // namespace rivulet
