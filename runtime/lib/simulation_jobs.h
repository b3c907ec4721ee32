#pragma once
// Each kind of scene simulation adds its jobs to a frame graph the same way: one function per system,
// after the frame's simulate.begin, returning its last job (SceneSimulation wraps them in simulate.begin
// and simulate.end). `particles` and the system must outlive the graph. (* = parallel)
//   streams  simulate.integrate*                       (systems/sim/stream_sim.h)
//   SPH      simulate.sph, running per substep the nested phases sph.substep, sph.grid_count*, ...,
//            sph.integrate* in the order the solver asks for them (systems/sim/sph_simulation.h)
//   diffuse  diffuse.update* -> diffuse.compact -> diffuse.emit_count* -> diffuse.emit_offsets
//            -> diffuse.compact_fill* -> diffuse.emit*  (systems/diffuse/diffuse_simulation.h)
#include "runtime/lib/frame_graph.h"
#include "systems/diffuse/diffuse_simulation.h"
#include "systems/particles/particle_set.h"
#include "systems/sim/sph_simulation.h"
#include "systems/sim/stream_sim.h"

namespace rivulet {

FrameGraph::JobId add_stream_jobs(FrameGraph& graph, StreamSimulation& stream, ParticleSet& particles,
                                  FrameGraph::JobId after);

// SPH's frame is no fixed graph (its substeps and solver iterations follow the flow): the serial job
// simulate.sph asks the simulation for its phases one by one (SphSimulation::next_phase) and runs each as
// a nested job of the graph, so a trace shows every phase under its own name.
FrameGraph::JobId add_sph_jobs(FrameGraph& graph, SphSimulation& sph, ParticleSet& particles,
                               FrameGraph::JobId after);

// The diffuse object's phases, one job each; `sprites` is the one after which the frame's sprites are
// final (DiffuseSimulation::kSprites).
struct DiffuseJobs {
    FrameGraph::JobId sprites, last;
};
DiffuseJobs add_diffuse_jobs(FrameGraph& graph, DiffuseSimulation& diffuse, ParticleSet& particles,
                             FrameGraph::JobId after);

}  // namespace rivulet
