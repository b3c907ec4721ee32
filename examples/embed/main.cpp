// Surfaces for a simulation that is not Rivulet's: a host program hands its particles over each frame
// and gets a mesh back, from one extractor whose workspace is reused; then the same frames through the
// frame pipeline, where the next frame is simulated and meshed while this one is drawn. Here the "host"
// is Rivulet's own dam break, stepped through the public API; any (x, y, z) array works the same way.
//   embed [FRAMES] [THREADS]
#include <rivulet/rivulet.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

// The host's own particle layout: x y z interleaved.
void copy_positions(const rivulet::PositionsView& p, std::vector<float>& xyz) {
    xyz.resize(3 * p.size());
    for (std::size_t i = 0; i < p.size(); ++i)
        xyz[3 * i] = p.x[i], xyz[3 * i + 1] = p.y[i], xyz[3 * i + 2] = p.z[i];
}

void print_frame(const char* what, unsigned long long f, std::size_t particles,
                 const rivulet::MeshView& mesh) {
    std::printf("%s %llu: %zu particles -> %zu vertices, %zu triangles, hash %016llx\n", what, f, particles,
                mesh.vertex_count(), mesh.triangle_count(),
                static_cast<unsigned long long>(rivulet::mesh_hash(mesh)));
}

}  // namespace

int main(int argc, char** argv) {
    const int frames = argc > 1 ? std::atoi(argv[1]) : 3;
    const int threads = argc > 2 ? std::atoi(argv[2]) : 0;
    try {
        rivulet::Simulation sim("dambreak", 30, threads);
        rivulet::SurfaceExtractor extractor;
        rivulet::SurfaceSettings settings;  // marching slices
        settings.radius = sim.particle_radius();
        settings.threads = threads;
        std::vector<float> xyz;
        for (int f = 0; f < frames; ++f) {
            sim.step();
            copy_positions(sim.positions(), xyz);
            const rivulet::MeshView mesh = extractor.extract(xyz, settings);
            print_frame("frame", static_cast<unsigned long long>(f), xyz.size() / 3, mesh);
        }
        // The same frames again, pipelined: `render` (here a print) runs on this thread while a worker
        // steps and meshes the next frame.
        rivulet::Simulation again("dambreak", 30, threads);
        rivulet::SurfacePipeline pipeline(settings);
        pipeline.run(
            static_cast<std::uint64_t>(frames),
            [&](std::uint64_t, std::vector<float>& out) {
                again.step();
                copy_positions(again.positions(), out);
            },
            [](std::uint64_t f, std::span<const float> particles, const rivulet::MeshView& mesh) {
                print_frame("pipelined frame", static_cast<unsigned long long>(f), particles.size() / 3,
                            mesh);
            });
        // Errors are rivulet::Error, with the command line's message.
        try {
            extractor.extract(std::vector<float>{}, settings);
        } catch (const rivulet::Error& e) {
            std::printf("empty input: %s\n", e.what());
        }
    } catch (const rivulet::Error& e) {
        std::fprintf(stderr, "embed: %s\n", e.what());
        return 1;
    }
    return 0;
}
