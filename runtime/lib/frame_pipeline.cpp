#include "runtime/lib/frame_pipeline.h"

#include <fmt/format.h>
#include <tbb/flow_graph.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <utility>

#include "systems/particles/particle_hash.h"
#include "systems/render/png_writer.h"
#include "systems/render/video_writer.h"

namespace rivulet {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// A picture queued for the video encoder: its ring buffer and frame index.
struct VideoFrame {
    std::uint32_t buffer = 0, index = 0;
};

}  // namespace

// Pictures waiting for their PNG encode: three buffers so the main thread rarely waits for an encoder.
// An encode that fails (disk full, unwritable path) keeps its error for the main thread, so waiting never
// throws (the destructor waits too) and the run stops with the message.
struct FramePipeline::PngRing {
    static constexpr int kBuffers = 3;
    struct Buffer {
        AlignedArray<std::uint8_t> rgba;
        std::string path;
        tbb::task_group encode;
        std::exception_ptr error;

        // Waits for this buffer's encode; rethrows its failure.
        void finish() {
            encode.wait();
            if (error) std::rethrow_exception(std::exchange(error, nullptr));
        }
    };
    std::array<Buffer, kBuffers> buffers;
    int width = 0, height = 0;

    void finish_all() {
        for (auto& b : buffers) b.encode.wait();
        for (auto& b : buffers) b.finish();
    }
    ~PngRing() {
        for (auto& b : buffers) b.encode.wait();
    }
};

// Pictures waiting for the video encoder. A video needs its frames in order, so one serial flow-graph
// node encodes them one at a time from its FIFO (a worker, or the main thread while it waits); three
// buffers let the main thread render ahead of it. As with PNGs, a failed encode keeps its error for the
// main thread, and the frames after it are dropped.
struct FramePipeline::VideoRing {
    static constexpr std::uint64_t kBuffers = 3;
    VideoWriter writer;
    std::array<AlignedArray<std::uint8_t>, kBuffers> rgba;
    std::size_t bytes = 0;
    std::uint64_t submitted = 0;            // main thread only
    std::atomic<std::uint64_t> encoded{0};  // frames the encoder is done with (buffers free again)
    std::atomic<bool> failed{false};
    std::exception_ptr error;  // set once by the encoder before `failed`
    bool finished = false;     // main thread only
    tbb::flow::graph graph;
    tbb::flow::function_node<VideoFrame> encoder;

    template <class Encode>
    explicit VideoRing(Encode encode) : encoder(graph, tbb::flow::serial, std::move(encode)) {}
    // Waits for every queued frame; rethrows an encoder failure.
    void wait() {
        graph.wait_for_all();
        if (failed.load(std::memory_order_acquire) && error)
            std::rethrow_exception(std::exchange(error, nullptr));
    }
    ~VideoRing() { graph.wait_for_all(); }  // before the node and the buffers go
};

FramePipeline::FramePipeline(const SceneDesc& scene, const PipelineSettings& config)
    : scene_(scene), config_(config) {
    // First of all, so that a bad path or size fails before anything slow is built.
    if (!config_.video_path.empty()) {
        if (!config_.render)
            throw std::invalid_argument("a video needs rendering: PipelineSettings::render is off");
        open_video();
    }
    sim_ = std::make_unique<SceneSimulation>(scene_, config_.inputs);
    // Traced, the render's passes are zones too: GL is finished after each to time it.
    if (config_.trace) config_.screen.time_passes = true;
    // Every thread that may run a job of the method gets its scratch now, so no frame allocates it later.
    surface_ = make_surface_system(
        {config_.method, config_.scan, config_.slices, config_.screen, config_.volume, {}}, scene_,
        static_cast<std::size_t>(tbb::this_task_arena::max_concurrency()), sim_.get());
    for (FrameSlot& slot : slots_) {
        const HeightFieldView pool = sim_->pool_view();
        slot.pool_heights.reserve(std::max<std::size_t>(pool.heights.size(), 1));
        slot.pool = pool;
        slot.pool.heights = slot.pool_heights.span(pool.heights.size());
    }
    build_graph();
    if (config_.trace) {
        graph_.attach_trace(config_.trace);
        trace_render_ = config_.trace->intern("render");
        trace_png_ = config_.trace->intern("png_encode");
        trace_video_ = config_.trace->intern("video_encode");
        const char* parts[] = {"render.upload", "render.volume_upload",   "render.shadow",
                               "render.scene",  "render.water_thickness", "render.water",
                               "render.screen", "render.volume",          "render.diffuse",
                               "render.finish"};
        for (std::size_t i = 0; i < trace_parts_.size(); ++i)
            trace_parts_[i] = config_.trace->intern(parts[i]);
        const char* screen_parts[] = {"screen.copy",      "screen.depth",     "screen.smoothing",
                                      "screen.thickness", "screen.composite", "screen.spray"};
        for (std::size_t i = 0; i < trace_screen_parts_.size(); ++i)
            trace_screen_parts_[i] = config_.trace->intern(screen_parts[i]);
    }
    if (config_.render) {
        renderer_ = std::make_unique<Renderer>(config_.size);
        renderer_->set_scene(scene_);
        renderer_->set_time_passes(config_.trace != nullptr);
        surface_->prepare_renderer(*renderer_);
        if (!config_.out_dir.empty()) {
            std::filesystem::create_directories(config_.out_dir);
            png_ = std::make_unique<PngRing>();
            png_->width = renderer_->width(), png_->height = renderer_->height();
            for (auto& b : png_->buffers) {
                b.rgba.reserve(std::size_t(png_->width) * png_->height * 4);
                b.path.reserve(config_.out_dir.size() + 64);
            }
        }
    }
}

FramePipeline::~FramePipeline() = default;

void FramePipeline::open_video() {
    // One picture per simulated frame, so the video plays in real time at the scene's own rate.
    const double fps = 1.0 / double(scene_.dt);
    if (!(fps <= VideoWriter::kMaxFps))
        throw std::runtime_error(fmt::format(
            "cannot write video '{}': the scene's dt of {} s makes {:.0f} frames per second, more than the "
            "{} a video may have",
            config_.video_path, scene_.dt, fps, VideoWriter::kMaxFps));
    video_ = std::make_unique<VideoRing>([this](const VideoFrame& f) {
        VideoRing& v = *video_;
        if (!v.failed.load(std::memory_order_relaxed)) {
            const std::int64_t t = config_.trace ? config_.trace->now_ns() : 0;
            try {
                v.writer.write(v.rgba[f.buffer].span(v.bytes));
            } catch (...) {
                v.error = std::current_exception();
                v.failed.store(true, std::memory_order_release);
            }
            if (config_.trace) config_.trace->record(trace_video_, f.index, -1, t, config_.trace->now_ns());
        }
        v.encoded.fetch_add(1, std::memory_order_release);
    });
    video_->writer.open(config_.video_path, config_.size.width, config_.size.height, fps);
    video_->bytes = std::size_t(config_.size.width) * std::size_t(config_.size.height) * 4u;
    for (auto& b : video_->rgba) b.reserve(video_->bytes);
}

void FramePipeline::finish_video() {
    if (!video_ || video_->finished) return;
    video_->finished = true;
    video_->wait();
    video_->writer.finish();
}

const VideoWriter* FramePipeline::video() const {
    return video_ ? &video_->writer : nullptr;
}

void FramePipeline::build_graph() {
    sim_end_ = sim_->add_jobs(graph_);
    const auto positions = [this] { return sim_->particles().positions(); };
    if (sim_->sph())
        surface_->use_particle_volumes([this] {
            const SphSimulation& sph = *sim_->sph();
            return ParticleVolumes{sph.density(), sph.particle_mass()};
        });
    const FrameGraph::JobId surface = surface_->add_jobs(
        graph_, positions, [this] { return target_slot_; }, sim_->surface_input());
    // Hand-over data of the slot: pool heights copied (the simulation moves on), counters, hash.
    graph_.serial("upload_staging",
                  [this] {
                      FrameSlot& slot = slots_[target_slot_];
                      const HeightFieldView pool = sim_->pool_view();
                      std::copy(pool.heights.begin(), pool.heights.end(), slot.pool_heights.data());
                      slot.particles = static_cast<std::uint32_t>(sim_->particles().size());
                      slot.frame = sim_->last_frame();
                      slot.inputs = sim_->last_inputs();
                      if (config_.hash_frames) slot.hash = surface_->output_hash(target_slot_);
                      slot.particle_hash = config_.hash_frames ? particle_hash(sim_->particles()) : 0;
                  },
                  {surface, sim_end_});
    if (graph_.job_count() > kMaxFrameJobs)
        throw std::logic_error("frame graph has more jobs than kMaxFrameJobs");
}

void FramePipeline::warmup() {
    sim_->step_serial(scene_.warmup_frames);
}

void FramePipeline::extract(int slot, std::uint32_t frame_index, bool async) {
    target_slot_ = slot;
    graph_.set_frame(frame_index);
    graph_.start();
    if (!async) finish_extract(slot);
}

void FramePipeline::finish_extract(int slot) {
    graph_.wait();
    const FrameSlot& s = slots_[slot];
    pending_ = {};
    pending_.frame = s.frame;
    pending_.particles = s.particles;
    const SurfaceStats stats = surface_->stats(slot);
    pending_.groups = stats.groups;
    pending_.isolated = stats.isolated;
    pending_.triangles = stats.triangles;
    pending_.pool_exhausted = stats.pool_exhausted;
    pending_.hash = s.hash;
    pending_.particle_hash = s.particle_hash;
    pending_.inputs = s.inputs;
    if (const SphSimulation* sph = sim_->sph()) {
        pending_.sph_substeps = static_cast<std::uint32_t>(sph->substeps());
        pending_.sph_iterations =
            static_cast<std::uint32_t>(sph->divergence_iterations() + sph->density_iterations());
        pending_.sph_density_error = sph->density_error();
    }
    pending_.extract_ms = graph_.last_run_ms();
    for (FrameGraph::JobId j = 0; j < graph_.job_count(); ++j) pending_.job_ms[j] = graph_.job_ms(j);
}

// The parts were timed one after another (GL finished after each), so they are laid end to end from the
// draw's start; the screen-space pass's own parts likewise inside render.screen.
void FramePipeline::trace_render_parts(std::uint32_t frame, std::int64_t begin_ns) {
    std::int64_t at = begin_ns;
    const auto lay = [&](std::uint16_t name, double ms) {
        const std::int64_t end = at + static_cast<std::int64_t>(ms * 1e6);
        if (end > at) config_.trace->record(name, frame, -1, at, end);
        at = end;
    };
    const RenderTimings& t = renderer_->timings();
    const double parts[] = {t.upload, t.volume_upload, t.shadow, t.scene,   t.water_thickness,
                            t.water,  t.screen,        t.volume, t.diffuse, t.finish};
    static_assert(std::size(parts) == std::tuple_size_v<decltype(trace_parts_)>);
    for (std::size_t i = 0; i < trace_parts_.size(); ++i) {
        if (i == 6 && surface_->method() == SurfaceMethod::kScreen) {
            const std::int64_t screen_begin = at;
            const ScreenFluidTimings& s = renderer_->screen_fluid().timings();
            const double screen[] = {s.copy_scene, s.depth, s.smoothing, s.thickness, s.composite, s.spray};
            for (std::size_t k = 0; k < trace_screen_parts_.size(); ++k)
                lay(trace_screen_parts_[k], screen[k]);
            at = screen_begin;
        }
        lay(trace_parts_[i], parts[i]);
    }
}

void FramePipeline::render(int slot, int frame_index) {
    if (!renderer_) return;
    FrameView view = slots_[slot].view(scene_.particle_radius);
    surface_->fill_view(slot, view);
    renderer_->set_container_offset(slots_[slot].inputs.container_offset);  // the slosh tank swings
    if (scene_.simulation == SimulationKind::kDiffuse) {
        // The colliders where the frame's simulation left them: a pure function of the scene and frame.
        std::array<Vec3f, kMaxMovers> at{};
        const std::size_t n = std::min(scene_.diffuse.colliders.size(), at.size());
        for (std::size_t c = 0; c < n; ++c)
            at[c] = diffuse_collider_position(scene_.diffuse.colliders[c],
                                              double(slots_[slot].frame + 1) * scene_.dt);
        renderer_->set_mover_offsets(std::span(at.data(), n));
    }
    const std::int64_t gl_begin = config_.trace ? config_.trace->now_ns() : 0;
    renderer_->render(view);
    if (config_.trace) trace_render_parts(static_cast<std::uint32_t>(frame_index), gl_begin);
    if (video_ && !video_->finished) {
        VideoRing& v = *video_;
        // The buffer's previous frame must be encoded; it nearly always is (the encoder keeps up).
        if (v.submitted - v.encoded.load(std::memory_order_acquire) >= VideoRing::kBuffers)
            v.graph.wait_for_all();
        if (v.failed.load(std::memory_order_acquire)) v.wait();  // throws the encoder's error
        const auto buffer = static_cast<std::uint32_t>(v.submitted % VideoRing::kBuffers);
        renderer_->read_rgba(v.rgba[buffer].span(v.bytes));
        v.encoder.try_put({buffer, static_cast<std::uint32_t>(frame_index)});
        ++v.submitted;
    }
    if (!png_) return;
    auto& buf = png_->buffers[static_cast<std::size_t>(frame_index % PngRing::kBuffers)];
    buf.finish();  // the encode that last used this buffer
    renderer_->read_rgba(buf.rgba.span(std::size_t(png_->width) * png_->height * 4));
    char name[64];
    std::snprintf(name, sizeof name, "/frame_%05d.png", frame_index);
    buf.path.assign(config_.out_dir);
    buf.path.append(name);
    buf.encode.run([&buf, this, frame_index] {
        const std::int64_t t = config_.trace ? config_.trace->now_ns() : 0;
        try {
            write_png_rgba(buf.path, png_->width, png_->height,
                           buf.rgba.span(std::size_t(png_->width) * png_->height * 4), config_.png_level);
        } catch (...) {
            buf.error = std::current_exception();
        }
        if (config_.trace)
            config_.trace->record(trace_png_, static_cast<std::uint32_t>(frame_index), -1, t,
                                  config_.trace->now_ns());
    });
}

void FramePipeline::run(int frames, const std::function<void(int)>& on_frame) {
    if (frames <= 0) return;
    const std::size_t base = records_.size();
    records_.reserve(base + static_cast<std::size_t>(frames));
    int slot = 0;
    const auto index = [base](int i) {
        return static_cast<std::uint32_t>(base + static_cast<std::size_t>(i));
    };
    extract(slot, index(0), false);
    auto last_done = std::chrono::steady_clock::now();
    for (int i = 0; i < frames; ++i) {
        FrameRecord rec = pending_;
        const bool more = i + 1 < frames;
        const int next = slot ^ 1;
        if (more && config_.pipelined)
            extract(next, index(i + 1), true);  // workers fill the other slot meanwhile
        const auto r0 = std::chrono::steady_clock::now();
        const std::int64_t t0 = config_.trace ? config_.trace->now_ns() : 0;
        render(slot, static_cast<int>(index(i)));
        if (config_.trace && renderer_)
            config_.trace->record(trace_render_, index(i), -1, t0, config_.trace->now_ns());
        rec.render_ms = renderer_ ? ms_since(r0) : 0.0;
        if (more) {
            if (config_.pipelined) {
                finish_extract(next);
            } else {
                extract(next, index(i + 1), false);
            }
        }
        const auto now = std::chrono::steady_clock::now();
        rec.frame_ms = std::chrono::duration<double, std::milli>(now - last_done).count();
        last_done = now;
        records_.push_back(rec);
        slot = next;
        if (on_frame) on_frame(i);
    }
    if (png_) png_->finish_all();
    if (video_ && !video_->finished) video_->wait();
}

}  // namespace rivulet
