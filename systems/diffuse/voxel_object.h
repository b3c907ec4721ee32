#pragma once
// The representation layer of a diffuse object (Juckel & Beckhaus, §4.1-4.2): the mesh's solid voxels,
// each with a particle colour and the index of its material, the attribute set it shares with the other
// voxels of its region. A palette rather than every attribute per voxel keeps a 256^3 grid at 6 bytes a
// voxel.
#include <cstdint>
#include <string>
#include <vector>

#include "jobs/diffuse_particles.h"
#include "systems/diffuse/colored_mesh.h"
#include "systems/diffuse/diffuse_desc.h"
#include "systems/diffuse/voxelizer.h"

namespace rivulet {

struct VoxelObject {
    VoxelGridShape shape;                 // object space: the rest pose, before FrameInputs' offset
    std::vector<std::uint16_t> material;  // per voxel; kNoMaterial outside the mesh
    std::vector<std::uint32_t> rgba;      // per voxel: the particle colour, alpha included
    std::vector<std::uint32_t> inside;    // indices of the voxels inside the mesh, ascending
    std::vector<VoxelMaterial> materials;
};

// The mesh a DiffuseDesc names: a built-in one ("ghost", "box", "sphere", "torus", "bunny") or a file,
// scaled and placed. Throws std::runtime_error when a file cannot be read.
ColoredMesh load_diffuse_mesh(const std::string& name, float scale, Vec3f position);

// Voxelizes the mesh and applies the default attributes and the regions. `dt` sets each material's
// emission per frame. Throws std::invalid_argument for an open mesh or bad attributes.
VoxelObject build_voxel_object(const DiffuseDesc& desc, const ColoredMesh& mesh, float dt);

// Throws std::invalid_argument naming the field when an attribute set is out of range (scene checks).
void validate_voxel_attributes(const VoxelAttributesDesc& a, const std::string& where);

// Throws std::invalid_argument naming the field when the desc is out of range (resolution, scale,
// regions, colliders, every region's attributes over the defaults), without voxelizing anything.
void validate_diffuse_desc(const DiffuseDesc& desc, const std::string& where);

// RGBA8 from [0, 1] channels (r in the low byte).
std::uint32_t pack_rgba(float r, float g, float b, float a);

}  // namespace rivulet
