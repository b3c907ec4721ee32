// Surfaces for a simulation that is not Rivulet's: a host program hands its particles over each frame
// and gets a mesh back, from one extractor whose workspace is reused. Here the "host" is Rivulet's own
// dam break, stepped through the public API; any (x, y, z) array works the same way.
//   embed [FRAMES] [THREADS]
#include <rivulet/rivulet.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

int main(int argc, char** argv) {
    const int frames = argc > 1 ? std::atoi(argv[1]) : 3;
    const int threads = argc > 2 ? std::atoi(argv[2]) : 0;
    try {
        rivulet::Simulation sim("dambreak", 30, threads);
        rivulet::SurfaceExtractor extractor;
        rivulet::SurfaceSettings settings;  // marching slices
        settings.radius = sim.particle_radius();
        settings.threads = threads;
        std::vector<float> xyz;  // the host's own particle layout: x y z interleaved
        for (int f = 0; f < frames; ++f) {
            sim.step();
            const rivulet::PositionsView p = sim.positions();
            xyz.resize(3 * p.size());
            for (std::size_t i = 0; i < p.size(); ++i)
                xyz[3 * i] = p.x[i], xyz[3 * i + 1] = p.y[i], xyz[3 * i + 2] = p.z[i];
            const rivulet::MeshView mesh = extractor.extract(xyz, settings);
            std::printf("frame %d: %zu particles -> %zu vertices, %zu triangles, hash %016llx\n", f, p.size(),
                        mesh.vertex_count(), mesh.triangle_count(),
                        static_cast<unsigned long long>(rivulet::mesh_hash(mesh)));
        }
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
