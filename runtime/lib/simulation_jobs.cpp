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

DiffuseJobs add_diffuse_jobs(FrameGraph& graph, DiffuseSimulation& d, ParticleSet& ps,
                             FrameGraph::JobId after) {
    DiffuseJobs jobs{after, after};
    FrameGraph::JobId& last = jobs.last;
    for (std::size_t p = 0; p < DiffuseSimulation::kPhaseCount; ++p) {
        const DiffusePhase& phase = DiffuseSimulation::kPhases[p];
        if (phase.parallel)
            last = graph.parallel(
                phase.job, [&d, &ps, p] { return d.phase_blocks(p, ps); },
                [&d, &ps, p](std::size_t b) { d.run_phase(p, b, ps); }, {last});
        else
            last = graph.serial(phase.job, [&d, &ps, p] { d.run_phase(p, 0, ps); }, {last});
        if (p == DiffuseSimulation::kSprites) jobs.sprites = last;
    }
    return jobs;
}

}  // namespace rivulet
