#include "runtime/lib/sprites_surface.h"

#include <algorithm>

#include "jobs/mesh_hash.h"
#include "systems/render/renderer.h"

namespace rivulet {
SpritesSurface::SpritesSurface(const SceneDesc& scene, std::function<SpriteSource()> source)
    : scene_(scene), source_(std::move(source)), max_particles_(scene.max_particles) {
    static_assert(DiffuseSimulation::kSpriteBuffers >= kFrameSlots,
                  "a slot's sprites must outlive the next frame");
    for (Staged& s : staged_) s.order.reserve(max_particles_);
    for (auto* a : {&keys_tmp_, &order_tmp_}) a->reserve(max_particles_);
    histograms_.reserve(std::max<std::size_t>(depth_sort_blocks(max_particles_), 1) * kRadixDigits);
}

DepthSortContext SpritesSurface::sort_context(std::size_t n, int slot) {
    DepthSortContext ctx;
    ctx.keys = frame_.depth_keys, ctx.keys_tmp = keys_tmp_.span(n);
    ctx.order = staged_[slot].order.span(n), ctx.order_tmp = order_tmp_.span(n);
    ctx.histograms = histograms_.span(depth_sort_blocks(n) * kRadixDigits);
    return ctx;
}

FrameGraph::JobId SpritesSurface::add_jobs(FrameGraph& graph, std::function<ConstPositions()>,
                                           std::function<int()> slot, FrameGraph::JobId after) {
    const bool sorted = this->sorted();
    const auto blocks = [this, sorted] { return sorted ? depth_sort_blocks(frame_.sprites.size()) : 0; };
    const auto begin = graph.serial("sprites.begin",
                                    [this, slot] {
                                        frame_ = source_();
                                        staged_[slot()].sprites = frame_.sprites;
                                    },
                                    {after});
    // The keys came with the sprites: the simulation made them while it had the positions at hand.
    FrameGraph::JobId last = begin;
    for (std::uint32_t pass = 0; pass < kRadixPasses; ++pass) {
        const std::string p = std::to_string(pass);
        const auto hist =
            graph.parallel("sprites.histogram" + p, blocks,
                           [this, pass, slot](std::size_t b) {
                               radix_histogram_block(sort_context(frame_.sprites.size(), slot()), pass, b);
                           },
                           {last});
        const auto prefix =
            graph.serial("sprites.prefix" + p,
                         [this, pass, sorted, slot] {
                             if (sorted) radix_prefix(sort_context(frame_.sprites.size(), slot()), pass);
                         },
                         {hist});
        last = graph.parallel("sprites.scatter" + p, blocks,
                              [this, pass, slot](std::size_t b) {
                                  radix_scatter_block(sort_context(frame_.sprites.size(), slot()), pass, b);
                              },
                              {prefix});
    }
    return last;
}

SurfaceStats SpritesSurface::stats(int slot) const {
    SurfaceStats st;
    st.isolated = static_cast<std::uint32_t>(staged_[slot].sprites.size());
    return st;
}

std::span<const std::uint32_t> SpritesSurface::order(int slot) const {
    const Staged& s = staged_[slot];
    return sorted() ? std::span<const std::uint32_t>(s.order.data(), s.sprites.size())
                    : std::span<const std::uint32_t>();
}

std::uint64_t SpritesSurface::output_hash(int slot) const {
    Hasher h;
    h.add(staged_[slot].sprites);
    h.add(order(slot));
    return h.digest();
}

void SpritesSurface::prepare_renderer(Renderer& renderer) const {
    renderer.set_diffuse_sprites(static_cast<std::uint32_t>(max_particles_));
}

void SpritesSurface::fill_view(int slot, FrameView& view) const {
    const Staged& s = staged_[slot];
    view.diffuse.sprites = s.sprites;
    view.diffuse.order = order(slot);
    view.diffuse.additive = scene_.diffuse.additive;
}

}  // namespace rivulet
