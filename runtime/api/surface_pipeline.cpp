#include <tbb/task_group.h>

#include <array>

#include "rivulet/pipeline.h"
#include "runtime/api/api_support.h"

namespace rivulet {

struct SurfacePipeline::Slots {
    struct Slot {
        std::vector<float> xyz;
        SurfaceExtractor extractor;
        MeshView mesh;
    };
    SurfaceSettings settings;
    bool overlap = true;
    std::array<Slot, 2> slot;  // frame f lives in slot f % 2
};

SurfacePipeline::SurfacePipeline(const SurfaceSettings& settings) : slots_(std::make_unique<Slots>()) {
    slots_->settings = settings;
}

SurfacePipeline::~SurfacePipeline() = default;
SurfacePipeline::SurfacePipeline(SurfacePipeline&&) noexcept = default;
SurfacePipeline& SurfacePipeline::operator=(SurfacePipeline&&) noexcept = default;

void SurfacePipeline::set_overlap(bool overlap) {
    slots_->overlap = overlap;
}

void SurfacePipeline::run(std::uint64_t frames, const Step& step, const Render& render) {
    if (!step || !render) throw Error("SurfacePipeline::run needs a step and a render function");
    Slots& s = *slots_;
    auto produce = [&](std::uint64_t f) {
        Slots::Slot& slot = s.slot[f % 2];
        step(f, slot.xyz);
        slot.mesh = slot.extractor.extract(slot.xyz, s.settings);
    };
    auto show = [&](std::uint64_t f) {
        const Slots::Slot& slot = s.slot[f % 2];
        render(f, slot.xyz, slot.mesh);
    };
    if (!s.overlap) {
        for (std::uint64_t f = 0; f < frames; ++f) produce(f), show(f);
        return;
    }
    if (frames == 0) return;
    produce(0);
    tbb::task_group next;  // frame f + 1's step and extraction, on a TBB worker while frame f renders
    for (std::uint64_t f = 0; f < frames; ++f) {
        if (f + 1 < frames) next.run([&produce, f] { produce(f + 1); });
        try {
            show(f);
        } catch (...) {
            try {
                next.wait();  // the frame in flight uses this object: let it finish
            } catch (...) {
            }
            throw;
        }
        next.wait();  // rethrows what frame f + 1's step or extraction threw
    }
}

}  // namespace rivulet
