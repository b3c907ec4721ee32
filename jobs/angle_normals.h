#pragma once
// Angle-weighted vertex normals (Janisz §3.2.5): each triangle adds its unit face normal to each of its
// vertices weighted by the triangle's angle at that vertex, so long thin triangles do not dominate.
#include <cstdint>
#include <span>

namespace rivulet {

// acc4[4 v ..] += sum over triangles of (angle at v) * (unit face normal) and 0, for positions4 (x, y, z
// and a pad per vertex) / triangles (3 indices each), 4 floats per vertex; the caller zeroes the sums of
// the vertices the triangles use (acc4 may be larger: it is indexed like positions4). Four floats a
// vertex make a triangle corner one vector load and one vector add. Degenerate triangles add nothing.
// Sums run in triangle order.
void accumulate_angle_normals(std::span<const float> positions4, std::span<const std::uint32_t> triangles,
                              std::span<float> acc4);
// The x86-64 baseline build (four triangles per vector), which accumulate_angle_normals runs where the CPU
// lacks AVX2 (eight per vector); tests compare the two byte for byte.
void accumulate_angle_normals_baseline(std::span<const float> positions4,
                                       std::span<const std::uint32_t> triangles, std::span<float> acc4);

// Normalises n (3 floats) in place; a zero vector becomes (0, 1, 0), +y up.
void normalize_or_up(float* n);

// vertices6[6 v ..] = position v, then its normal sum normalised (normalize_or_up), for positions4 and
// acc4 of four floats per vertex: the mesh's vertex records, written once.
void write_vertices(std::span<const float> positions4, std::span<const float> acc4,
                    std::span<float> vertices6);

}  // namespace rivulet
