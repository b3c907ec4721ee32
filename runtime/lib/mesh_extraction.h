#pragma once
// Offline meshing of one particle set (`rivulet mesh`): the jobs of one surface method (sphere scan
// conversion, or marching slices) in a frame graph run `repeat` times on the same particles; timings
// exclude file I/O.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "systems/io/particle_io.h"
#include "systems/scan/scan_mesh.h"
#include "systems/scan/scan_settings.h"
#include "systems/slices/slices_settings.h"
#include "systems/volume/volume_builder.h"

namespace rivulet {

struct MeshSettings {
    std::string method = "scan";  // "scan", "slices" or "volume"
    ScanSettings scan;            // v_top / v_bottom come from the particles' extent
    SlicesSettings slices;        // radius comes from `radius` below
    VolumeSettings volume;        // radius comes from `radius` below
    bool mesh_volume = true;      // volume: marching cubes on the grid (else the volume only, e.g. for .vdb)
    float radius = 0;             // 0: estimated from the particles
    int repeat = 1;
};

struct MeshResult {
    std::size_t particles = 0;
    float radius = 0;
    std::uint32_t groups = 0, isolated = 0;                // scan
    float voxel = 0, rc = 0, iso = 0;                      // slices; volume (rc: the kernel radius h)
    std::string slices_field;                              // slices: "spacing" or "classic"
    float spacing = 0;                                     // slices, spacing field: the spacing it used
    float anisotropy = 0, anisotropy_smoothing = 0;        // slices: the kernels' stretch (0: spheres)
    std::uint32_t blocks = 0;                              // slices: non-empty blocks
    std::uint64_t seeds = 0, cubes = 0;                    // slices: seed cubes, cubes swept
    double total_ms = 0;                                   // median graph wall time
    std::vector<std::pair<std::string, double>> stage_ms;  // medians
    TriangleMesh mesh;
    std::uint64_t hash = 0;                 // mesh_hash(mesh); a volume without a mesh: DensityVolume::hash
    std::unique_ptr<DensityVolume> volume;  // volume: the grid the mesh came from
};

MeshResult extract_mesh(const ParticleCloud& cloud, const MeshSettings& request);

}  // namespace rivulet
