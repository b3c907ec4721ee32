// Two readings of one density volume must agree: the GL raycast's depth, pixel by pixel, against rays cast
// on the CPU at the marching-cubes mesh of the same grid (Inácio et al. argue that the volume decouples
// simulation from rendering: any renderer or mesher can take it; these two must then see the same
// surface). The volume is built by the frame's jobs from particles that are not a lattice.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "jobs/counter_rng.h"
#include "runtime/lib/frame_graph.h"
#include "runtime/lib/volume_jobs.h"
#include "support/test_support.h"
#include "systems/render/camera.h"
#include "systems/render/renderer.h"
#include "systems/volume/volume_mesh.h"

namespace rivulet {
namespace {

constexpr int kW = 160, kH = 120;

struct Cloud {
    std::vector<float> x, y, z;
    ConstPositions view() const { return {x, y, z}; }
};

// A lumpy ball (jittered lattice, spacing 2 radius) with a smaller ball beside it.
Cloud lumpy_balls(float radius) {
    Cloud c;
    const float s = 2 * radius;
    std::uint64_t id = 0;
    const auto ball = [&](float cx, float cy, float cz, float r) {
        const int n = static_cast<int>(r / s) + 1;
        for (int k = -n; k <= n; ++k)
            for (int j = -n; j <= n; ++j)
                for (int i = -n; i <= n; ++i) {
                    const float x = s * float(i), y = s * float(j), z = s * float(k);
                    if (x * x + y * y + z * z > r * r) continue;
                    const float jitter = 0.3f * s;
                    c.x.push_back(cx + x + jitter * (counter_uniform(3, 0, id, 0) - 0.5f));
                    c.y.push_back(cy + y + jitter * (counter_uniform(3, 0, id, 1) - 0.5f));
                    c.z.push_back(cz + z + jitter * (counter_uniform(3, 0, id, 2) - 0.5f));
                    ++id;
                }
    };
    ball(-0.1f, 0.5f, 0.0f, 0.35f);
    ball(0.42f, 0.62f, 0.1f, 0.15f);
    return c;
}

// Nearest hit of the ray eye + t * ray (ray's forward component 1, so t is the view-axis depth) with the
// triangles, 0 when none (Möller & Trumbore).
struct Ray {
    double o[3], d[3];
};
double hit_triangle(const Ray& r, const float* a, const float* b, const float* c) {
    double e1[3], e2[3], p[3], q[3], s[3];
    for (int i = 0; i < 3; ++i) e1[i] = b[i] - a[i], e2[i] = c[i] - a[i], s[i] = r.o[i] - a[i];
    p[0] = r.d[1] * e2[2] - r.d[2] * e2[1], p[1] = r.d[2] * e2[0] - r.d[0] * e2[2],
    p[2] = r.d[0] * e2[1] - r.d[1] * e2[0];
    const double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    if (std::abs(det) < 1e-18) return 0;
    const double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
    if (u < 0 || u > 1) return 0;
    q[0] = s[1] * e1[2] - s[2] * e1[1], q[1] = s[2] * e1[0] - s[0] * e1[2],
    q[2] = s[0] * e1[1] - s[1] * e1[0];
    const double v = (r.d[0] * q[0] + r.d[1] * q[1] + r.d[2] * q[2]) / det;
    if (v < 0 || u + v > 1) return 0;
    const double t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
    return t > 0 ? t : 0;
}

// The mesh's depth per pixel (rows bottom to top, as the GL targets), by rays through pixel centres;
// each triangle tests only the pixels of its projected bounding box.
std::vector<double> mesh_depth(const TriangleMesh& mesh, const CameraDesc& cam) {
    const CameraBasis b = camera_basis(cam);
    const double hy = b.tan_half_fov_y, hx = hy * kW / kH;
    const auto ray = [&](int i, int j) {
        const double nx = (i + 0.5) / kW * 2 - 1, ny = (j + 0.5) / kH * 2 - 1;
        return Ray{{b.eye.x, b.eye.y, b.eye.z},
                   {b.forward.x + nx * hx * b.right.x + ny * hy * b.up.x,
                    b.forward.y + nx * hx * b.right.y + ny * hy * b.up.y,
                    b.forward.z + nx * hx * b.right.z + ny * hy * b.up.z}};
    };
    std::vector<double> depth(std::size_t(kW) * kH, 0.0);
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
        const float* v[3];
        double lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9};
        for (int k = 0; k < 3; ++k) {
            v[k] = &mesh.vertices[6 * std::size_t(mesh.indices[t + std::size_t(k)])];
            const double dx = v[k][0] - b.eye.x, dy = v[k][1] - b.eye.y, dz = v[k][2] - b.eye.z;
            const double d = dx * b.forward.x + dy * b.forward.y + dz * b.forward.z;
            const double sx = (dx * b.right.x + dy * b.right.y + dz * b.right.z) / (d * hx);
            const double sy = (dx * b.up.x + dy * b.up.y + dz * b.up.z) / (d * hy);
            const double px = (sx + 1) / 2 * kW - 0.5, py = (sy + 1) / 2 * kH - 0.5;
            lo[0] = std::min(lo[0], px), hi[0] = std::max(hi[0], px);
            lo[1] = std::min(lo[1], py), hi[1] = std::max(hi[1], py);
        }
        const int i0 = std::max(0, int(std::floor(lo[0])) - 1),
                  i1 = std::min(kW - 1, int(std::ceil(hi[0])) + 1);
        const int j0 = std::max(0, int(std::floor(lo[1])) - 1),
                  j1 = std::min(kH - 1, int(std::ceil(hi[1])) + 1);
        for (int j = j0; j <= j1; ++j)
            for (int i = i0; i <= i1; ++i) {
                const double t_hit = hit_triangle(ray(i, j), v[0], v[1], v[2]);
                double& d = depth[std::size_t(j) * kW + i];
                if (t_hit > 0 && (d == 0 || t_hit < d)) d = t_hit;
            }
    }
    return depth;
}

TEST(VolumeVsMesh, RaycastDepthMatchesTheMarchingCubesMeshOfTheSameGrid) {
    VolumeSettings s;
    s.radius = 0.02f;
    const Cloud cloud = lumpy_balls(s.radius);
    VolumeBuilder builder(s, cloud.x.size());
    DensityVolume volume;
    builder.prepare(volume);
    FrameGraph graph;
    add_volume_jobs(
        graph, builder, [&cloud] { return cloud.view(); }, [&volume]() -> DensityVolume& { return volume; });
    graph.run();
    ASSERT_GT(volume.stored, 0u);
    const float voxel = volume.grid.voxel;

    const TriangleMesh mesh = mesh_density_volume(volume.view());
    ASSERT_GT(mesh.triangle_count(), 1000u);
    const SceneDesc scene = test::facing_scene();
    Renderer r(RenderSettings{kW, kH});
    r.set_scene(scene);
    r.set_volume_raycast({});
    FrameView frame;
    frame.volume = volume.view();
    r.render(frame);
    std::vector<float> ray_depth(std::size_t(kW) * kH);
    r.volume_pass().read(VolumeBuffer::kDepth, ray_depth);
    const std::vector<double> mc_depth = mesh_depth(mesh, scene.camera);

    // Every pixel the mesh covers whose neighbours it covers too: the raycast hits it, within a voxel.
    // At the outline a ray grazes both surfaces, which may differ there by a fraction of a voxel, so
    // coverage may differ on a pixel of the outline only.
    const auto at = [](int i, int j) { return std::size_t(j) * kW + i; };
    int compared = 0, outline_only = 0;
    for (int j = 1; j + 1 < kH; ++j)
        for (int i = 1; i + 1 < kW; ++i) {
            const bool mesh_here = mc_depth[at(i, j)] > 0, ray_here = ray_depth[at(i, j)] > 0;
            const bool interior = mesh_here && mc_depth[at(i - 1, j)] > 0 && mc_depth[at(i + 1, j)] > 0 &&
                                  mc_depth[at(i, j - 1)] > 0 && mc_depth[at(i, j + 1)] > 0;
            if (interior) {
                ASSERT_TRUE(ray_here) << "pixel " << i << ", " << j;
                EXPECT_NEAR(ray_depth[at(i, j)], mc_depth[at(i, j)], voxel) << "pixel " << i << ", " << j;
                ++compared;
            } else if (mesh_here != ray_here) {
                // Not interior to the mesh: the ray's hit must itself be on the mesh's outline.
                bool near_mesh = false;
                for (int dj = -1; dj <= 1; ++dj)
                    for (int di = -1; di <= 1; ++di)
                        near_mesh = near_mesh || mc_depth[at(i + di, j + dj)] > 0;
                EXPECT_TRUE(near_mesh) << "raycast hit at " << i << ", " << j << " far from the mesh";
                ++outline_only;
            }
        }
    EXPECT_GT(compared, 800);
    EXPECT_LT(outline_only, compared / 10);
}

}  // namespace
}  // namespace rivulet
