#pragma once
// A density volume as an OpenVDB file, for the tools that read .vdb (Houdini, Blender, the OpenVDB
// command line tools). OpenVDB's headers stay in vdb_writer.cpp: they are heavy, and the project builds
// under several sanitizers.
#include <string>

#include "jobs/density_volume.h"
#include "systems/io/file_format_error.h"

namespace rivulet {

struct VdbWriteSettings {
    bool level_set = false;   // also write a narrow-band signed distance grid of the surface F = iso
    float half_width = 3.0f;  // narrow band half width, in voxels (at least 1)
};

// Writes `volume` as an OpenVDB FloatGrid named "density" of class fog volume, background 0, whose
// transform is a uniform scale by grid.voxel translated so that index (i, j, k) is the lattice sample
// (ox + voxel i, oy + voxel j, oz + voxel k). Every sample of a stored brick is an active value, the
// rest of space is inactive background. With options.level_set a second FloatGrid "surface" of class
// level set follows: the signed distance to F = iso in world units, negative inside the fluid (F > iso),
// in a narrow band of options.half_width voxels each side, background half_width * voxel. Both grids
// carry the metadata "creator" = "rivulet" and the float "iso".
// Throws FileFormatError (a std::runtime_error) naming the path when the volume is malformed (an atlas
// too small for its slots, a brick index out of range, a voxel that is not positive) or the file cannot
// be written; a partly written file is removed.
void write_vdb(const std::string& path, const DensityVolumeView& volume,
               const VdbWriteSettings& options = {});

}  // namespace rivulet
