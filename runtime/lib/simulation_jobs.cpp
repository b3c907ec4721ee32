#include "runtime/lib/simulation_jobs.h"

#include <memory>
#include <vector>

#include "jobs/particle_chunks.h"

namespace rivulet {
namespace {

constexpr ParticleChunks kIntegrateChunks{};

}  // namespace

FrameGraph::JobId add_stream_jobs(FrameGraph& graph, StreamSimulation& stream, ParticleSet& particles,
                                  FrameGraph::JobId after) {
    return graph.parallel(
        "simulate.integrate", [&particles] { return kIntegrateChunks.count(particles.size()); },
        [&stream, &particles](std::size_t c) {
            const ParticleRange r = kIntegrateChunks.range(c, particles.size());
            stream.integrate(particles, r.begin, r.end());
        },
        {after});
}

FrameGraph::JobId add_sph_jobs(FrameGraph& graph, SphSimulation& sph, ParticleSet& particles,
                               FrameGraph::JobId after) {
    // The nested jobs are made after their parent; the parent's body finds them here.
    auto phase_jobs = std::make_shared<std::vector<FrameGraph::JobId>>();
    const FrameGraph::JobId body = graph.serial(
        "simulate.sph",
        [&graph, &sph, &particles, phase_jobs] {
            const auto phases = sph.phases();
            for (std::size_t p = sph.next_phase(); p != SphSimulation::kPhaseCount; p = sph.next_phase())
                graph.run_nested((*phase_jobs)[p], phases[p].parallel ? sph.chunks() : std::size_t{1},
                                 [&sph, &particles, p](std::size_t c) { sph.run_phase(p, c, particles); });
        },
        {after});
    for (const SphPhase& phase : sph.phases()) phase_jobs->push_back(graph.nested(phase.name, body));
    return body;
}

FrameGraph::JobId add_diffuse_jobs(FrameGraph& graph, DiffuseSimulation& d, ParticleSet& ps,
                                   FrameGraph::JobId after) {
    const auto update = graph.parallel(
        "diffuse.update", [&d, &ps] { return d.update_blocks(ps); },
        [&d, &ps](std::size_t b) { d.update_block(b, ps); }, {after});
    const auto compact = graph.serial("diffuse.compact", [&d, &ps] { d.compact(ps); }, {update});
    const auto count = graph.parallel(
        "diffuse.emit_count", [&d] { return d.emit_blocks(); },
        [&d, &ps](std::size_t b) { d.emit_count_block(b, ps); }, {compact});
    const auto offsets = graph.serial("diffuse.emit_offsets", [&d, &ps] { d.emit_offsets(ps); }, {count});
    return graph.parallel(
        "diffuse.emit", [&d] { return d.emit_blocks(); }, [&d, &ps](std::size_t b) { d.emit_block(b, ps); },
        {offsets});
}

}  // namespace rivulet
