#pragma once
// A surface from particles, inside your own program: SurfaceExtractor runs one surface method's jobs (the
// same frame graph as `rivulet mesh`) on the particles you pass and keeps its workspace for the next
// call, so extracting frame after frame of a simulation allocates nothing once it is warm (slices: same
// settings, no more particles than before).
//
//   rivulet::SurfaceExtractor extractor;
//   rivulet::SurfaceSettings settings;           // marching slices, radius estimated from the particles
//   rivulet::MeshView mesh = extractor.extract(xyz, settings);   // xyz: x0 y0 z0 x1 y1 z1 ...
//   draw(mesh.vertices, mesh.indices);           // valid until the next extract()
//
// Errors throw rivulet::Error (<rivulet/error.h>).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

namespace rivulet {

// The surface methods (docs/marching_slices.md, docs/scan_conversion.md, docs/volume.md):
//   kSlices  marching slices (Rosenberg & Birdwell 2008): a smooth, closed, welded mesh of the field
//            around the particles; the default.
//   kScan    sphere scan conversion (the cylinders of seed 000): cheap, fixed topology, for streams.
//   kVolume  the density volume of Inácio et al. (W_poly6 on a sparse lattice), meshed by marching cubes.
enum class Method : std::uint8_t { kScan, kSlices, kVolume };

struct SurfaceSettings {
    Method method = Method::kSlices;
    float radius = 0;      // particle radius, world units; 0: estimated (half the median neighbour distance)
    float voxel = 0;       // slices: cube edge (0: radius / 2); volume: lattice spacing (0: h / 4)
    float anisotropy = 0;  // slices: anisotropic kernels (Yu & Turk 2013), longest over shortest axis in
                           // [1, 4]; 0: spheres
    int threads = 0;       // workers extract() runs on, the calling thread included; 0: every hardware thread
};

// A triangle mesh the extractor owns: valid until its next extract() or its destruction.
struct MeshView {
    std::span<const float> vertices;         // 6 floats a vertex: position x y z, then unit normal x y z
    std::span<const std::uint32_t> indices;  // 3 a triangle, counter-clockwise seen from outside the fluid
    float radius = 0;                        // the particle radius used (estimated when settings said 0)

    std::size_t vertex_count() const { return vertices.size() / 6; }
    std::size_t triangle_count() const { return indices.size() / 3; }
};

// XXH3-64 of the vertex bytes followed by the index bytes: the `hash` that `rivulet mesh --json` prints
// for the same particles and settings.
std::uint64_t mesh_hash(const MeshView& mesh);

class SurfaceExtractor {
  public:
    SurfaceExtractor();
    ~SurfaceExtractor();
    SurfaceExtractor(SurfaceExtractor&&) noexcept;
    SurfaceExtractor& operator=(SurfaceExtractor&&) noexcept;

    // The surface of `xyz` (3 floats a particle, interleaved; at least one particle, all finite). The
    // result depends on the particles and settings only, never on earlier calls; the same input gives
    // the same bytes at any thread count.
    MeshView extract(std::span<const float> xyz, const SurfaceSettings& settings);
    // The same from one array per coordinate (structure of arrays, like Rivulet's own particle store).
    MeshView extract(std::span<const float> x, std::span<const float> y, std::span<const float> z,
                     const SurfaceSettings& settings);

  private:
    struct Workspace;
    std::unique_ptr<Workspace> workspace_;
};

}  // namespace rivulet
