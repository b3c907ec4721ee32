#include "runtime/lib/sprites_surface.h"

#include <algorithm>

#include "jobs/mesh_hash.h"
#include "jobs/particle_chunks.h"
#include "systems/render/renderer.h"

namespace rivulet {
namespace {

// Far enough around the object's grid for the particles that drift out of it while they fade; beyond
// it depths clamp (still drawn, in a tie).
constexpr float kDepthMargin = 2.0f;
// Sprites the staging gather asks for before it reads them.
constexpr std::size_t kGatherAhead = 32;

}  // namespace

SpritesSurface::SpritesSurface(const SceneDesc& scene, std::function<std::span<const DiffuseSprite>()> source)
    : scene_(scene), source_(std::move(source)), max_particles_(scene.max_particles) {
    for (Staged& s : staged_) s.sprites.reserve(max_particles_);
    for (auto* a : {&keys_, &keys_tmp_, &order_, &order_tmp_}) a->reserve(max_particles_);
    histograms_.reserve(std::max<std::size_t>(depth_sort_blocks(max_particles_), 1) * kRadixDigits);
    // The camera is the scene's, fixed: the depth range of a ball around its target that holds the
    // object and its margin.
    const Vec3f eye = scene_.camera.eye;
    map_.origin = eye;
    map_.direction = normalize(scene_.camera.target - eye);
    const float reach = length(scene_.camera.target - eye);
    map_.depth_min = std::max(0.0f, reach - kDepthMargin - 2.0f);
    map_.depth_max = reach + kDepthMargin + 2.0f;
}

DepthSortContext SpritesSurface::sort_context(std::size_t n) {
    DepthSortContext ctx;
    ctx.map = map_;
    ctx.keys = keys_.span(n), ctx.keys_tmp = keys_tmp_.span(n);
    ctx.order = order_.span(n), ctx.order_tmp = order_tmp_.span(n);
    ctx.histograms = histograms_.span(depth_sort_blocks(n) * kRadixDigits);
    return ctx;
}

FrameGraph::JobId SpritesSurface::add_jobs(FrameGraph& graph, std::function<ConstPositions()>,
                                           std::function<int()> slot, FrameGraph::JobId after) {
    const bool sorted = !scene_.diffuse.additive;
    const auto blocks = [this, sorted] { return sorted ? depth_sort_blocks(frame_.size()) : 0; };
    const auto begin = graph.serial("sprites.begin",
                                    [this, slot] {
                                        frame_ = source_();
                                        staged_[slot()].count = frame_.size();
                                    },
                                    {after});
    FrameGraph::JobId last = graph.parallel(
        "sprites.keys", blocks,
        [this](std::size_t b) { depth_keys_block(sort_context(frame_.size()), frame_, b); }, {begin});
    for (std::uint32_t pass = 0; pass < kRadixPasses; ++pass) {
        const std::string p = std::to_string(pass);
        const auto hist = graph.parallel(
            "sprites.histogram" + p, blocks,
            [this, pass](std::size_t b) { radix_histogram_block(sort_context(frame_.size()), pass, b); },
            {last});
        const auto prefix = graph.serial("sprites.prefix" + p,
                                         [this, pass, sorted] {
                                             if (sorted) radix_prefix(sort_context(frame_.size()), pass);
                                         },
                                         {hist});
        last = graph.parallel(
            "sprites.scatter" + p, blocks,
            [this, pass](std::size_t b) { radix_scatter_block(sort_context(frame_.size()), pass, b); },
            {prefix});
    }
    return graph.parallel(
        "sprites.stage", [this] { return ParticleChunks{kChunk}.count(frame_.size()); },
        [this, slot, sorted](std::size_t c) {
            Staged& s = staged_[slot()];
            const ParticleRange r = ParticleChunks{kChunk}.range(c, frame_.size());
            DiffuseSprite* out = s.sprites.data();
            const std::uint32_t* order = order_.data();
            if (!sorted) {
                std::copy(frame_.begin() + std::ptrdiff_t(r.begin), frame_.begin() + std::ptrdiff_t(r.end()),
                          out + r.begin);
                return;
            }
            // Random reads: asked for well ahead, so many misses are in flight at once.
            const DiffuseSprite* in = frame_.data();
            const std::size_t ahead = std::min(r.end(), r.begin + kGatherAhead);
            for (std::size_t k = r.begin; k < ahead; ++k) __builtin_prefetch(in + order[k]);
            for (std::size_t k = r.begin; k < r.end(); ++k) {
                if (k + kGatherAhead < r.end()) __builtin_prefetch(in + order[k + kGatherAhead]);
                out[k] = in[order[k]];
            }
        },
        {last});
}

SurfaceStats SpritesSurface::stats(int slot) const {
    SurfaceStats st;
    st.isolated = static_cast<std::uint32_t>(staged_[slot].count);
    return st;
}

std::uint64_t SpritesSurface::output_hash(int slot) const {
    const Staged& s = staged_[slot];
    return hash_bytes(s.sprites.data(), s.count * sizeof(DiffuseSprite));
}

void SpritesSurface::prepare_renderer(Renderer& renderer) const {
    renderer.set_diffuse_sprites(static_cast<std::uint32_t>(max_particles_));
}

void SpritesSurface::fill_view(int slot, FrameView& view) const {
    const Staged& s = staged_[slot];
    view.diffuse.sprites = std::span<const DiffuseSprite>(s.sprites.data(), s.count);
    view.diffuse.additive = scene_.diffuse.additive;
}

}  // namespace rivulet
