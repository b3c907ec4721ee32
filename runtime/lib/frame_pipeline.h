#pragma once
// The frame loop: simulation and extraction of frame N+1 run as a frame graph on TBB workers while the
// main thread renders frame N from the other slot (DESIGN §1). PNG and video encoding run as tasks off the
// main thread. Everything is sized at construction; the steady state allocates nothing.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "runtime/lib/frame_graph.h"
#include "runtime/lib/frame_slot.h"
#include "runtime/lib/scene_simulation.h"
#include "runtime/lib/surface_system.h"
#include "runtime/lib/trace_recorder.h"
#include "systems/particles/particle_set.h"
#include "systems/render/renderer.h"
#include "systems/render/video_writer.h"
#include "systems/scenes/scene.h"

namespace rivulet {

struct PipelineSettings {
    SurfaceMethod method = SurfaceMethod::kScan;
    ScanSettings scan;      // v_top / v_bottom / radius are taken from the scene
    SlicesSettings slices;  // radius is taken from the scene
    ScreenFluidSettings screen;
    VolumeSettings volume;     // radius is taken from the scene
    bool render = true;        // false: extraction only (benchmarks, tests without GL)
    bool pipelined = true;     // false: extract then render, one after the other
    bool hash_frames = false;  // frame_output_hash per frame (determinism tests, replay)
    std::string out_dir;       // PNG frames go here when not empty
    int png_level = 1;
    // Every rendered frame also goes into this video (docs/video.md) when not empty, at the scene's
    // frame rate (1 / dt). Needs `render`.
    std::string video_path;
    RenderSettings size;
    TraceRecorder* trace = nullptr;  // zones of every job, render, PNG and video encode when set
    // Outside inputs of each simulated frame (warm-up included); empty: the scene's scripted inputs.
    // Replay feeds recorded inputs here. Called on a worker; must not allocate.
    std::function<FrameInputs(std::uint64_t sim_frame)> inputs;
};

inline constexpr std::size_t kMaxFrameJobs = 48;

struct FrameRecord {
    std::uint64_t frame = 0;
    std::uint32_t particles = 0, groups = 0, isolated = 0;  // groups: slices' non-empty blocks
    std::uint64_t triangles = 0;
    std::uint32_t pool_exhausted = 0;  // scan: entries left isolated because every cylinder was in use
    std::uint64_t hash = 0;            // the surface's buffers (when config.hash_frames)
    std::uint64_t particle_hash = 0;   // the particle arrays the surface was extracted from (idem)
    FrameInputs inputs;
    // SPH scenes: the frame's substeps, solver iterations (divergence + density corrections) and the
    // largest average density error a substep's solve left (fraction of rest density; DFSPH).
    std::uint32_t sph_substeps = 0, sph_iterations = 0;
    double sph_density_error = 0;
    double extract_ms = 0;  // frame graph wall time (simulation + extraction)
    double render_ms = 0;   // main thread: upload + draw + read-back (0 when not rendering)
    double frame_ms = 0;    // wall time between consecutive frames leaving the loop
    std::array<double, kMaxFrameJobs> job_ms{};
};

class FramePipeline {
  public:
    // Builds simulation, surface method, slots, frame graph and (if config.render) the renderer on the
    // calling thread, which becomes the render thread. Throws on invalid settings or GL failure, and
    // when the video cannot be created (checked first, so a bad path fails at once).
    FramePipeline(const SceneDesc& scene, const PipelineSettings& config);
    ~FramePipeline();

    // Simulates the scene's warm-up frames (no extraction) so frame 0 shows the steady state.
    void warmup();
    // Runs `frames` frames; records go to records(). `on_frame(i)` is called on the main thread after
    // each frame (progress bars); it must not allocate in the steady state.
    void run(int frames, const std::function<void(int)>& on_frame = {});
    // Reserves records for this many frames up front (run() grows them otherwise).
    void reserve_records(std::size_t frames) { records_.reserve(frames); }
    // Encodes the frames still queued, drains the encoder and completes the video file; frames run
    // later are not added. Throws on a write failure. The destructor does this too, but quietly.
    void finish_video();
    // The video being written (or finished); null without config.video_path.
    const VideoWriter* video() const;

    const std::vector<FrameRecord>& records() const { return records_; }
    const FrameGraph& graph() const { return graph_; }
    const SurfaceSystem& surface() const { return *surface_; }
    const PipelineSettings& config() const { return config_; }
    const ParticleSet& particles() const { return sim_->particles(); }
    const FrameSlot& slot(int i) const { return slots_[i]; }
    Renderer* renderer() { return renderer_.get(); }
    const SceneDesc& scene() const { return scene_; }
    std::uint64_t next_sim_frame() const { return sim_->next_frame(); }

  private:
    void build_graph();
    void open_video();
    void extract(int slot, std::uint32_t frame_index, bool async);
    void finish_extract(int slot);
    void render(int slot, int frame_index);
    void trace_render_parts(std::uint32_t frame, std::int64_t begin_ns);

    SceneDesc scene_;
    PipelineSettings config_;
    std::unique_ptr<SceneSimulation> sim_;
    std::unique_ptr<SurfaceSystem> surface_;
    std::array<FrameSlot, kFrameSlots> slots_;
    int target_slot_ = 0;
    FrameGraph graph_;
    FrameGraph::JobId sim_end_ = 0;
    std::unique_ptr<Renderer> renderer_;
    struct PngRing;
    std::unique_ptr<PngRing> png_;
    struct VideoRing;
    std::unique_ptr<VideoRing> video_;
    std::vector<FrameRecord> records_;
    FrameRecord pending_;  // extraction figures of the frame in flight
    std::uint16_t trace_render_ = 0, trace_png_ = 0, trace_video_ = 0;
    // The render's parts (RenderTimings order) and the screen-space pass's (ScreenFluidTimings order).
    std::array<std::uint16_t, 10> trace_parts_{};
    std::array<std::uint16_t, 6> trace_screen_parts_{};
};

}  // namespace rivulet
