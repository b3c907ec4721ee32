#include "perf/support/falling_stream.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "jobs/counter_rng.h"

namespace rivulet::perf {
namespace {
constexpr std::uint64_t kSeed = 2008;
}

ParticleSet falling_stream(std::size_t particles, std::size_t fixed_streams) {
    constexpr float kDrop = 1.5f, kGravity = 9.81f, kVx = 0.4f, kVy = 0.3f;  // nozzle velocity (kVx, -kVy)
    constexpr float kPitch = 0.35f;                                          // between parallel streams
    constexpr std::size_t kPerStream = 1000, kMaxStreams = 64;
    const std::size_t slices = static_cast<std::size_t>(kDrop / kStreamRadius);  // 75
    const std::size_t streams =
        fixed_streams > 0
            ? fixed_streams
            : std::clamp<std::size_t>((particles + kPerStream - 1) / kPerStream, 1, kMaxStreams);
    const auto grid = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(streams))));
    const std::size_t per_slice = (particles + streams * slices - 1) / (streams * slices);
    // Sunflower disk radius so each particle covers about one radius squared.
    const float disk =
        kStreamRadius * std::sqrt(static_cast<float>(per_slice) / std::numbers::pi_v<float>) * 1.05f;
    constexpr float kGolden = 2.39996323f;

    ParticleSet set(particles);
    auto uniform = [](std::size_t i, std::uint64_t what) {  // [-1, 1)
        return 2.0f * counter_uniform(kSeed, 0, i, what) - 1.0f;
    };
    for (std::size_t i = 0; i < particles; ++i) {
        const std::size_t stream = i % streams;
        const std::size_t slice = (i / streams) % slices;
        const std::size_t k = i / (streams * slices);  // index within the slice's disk
        // Depth below the nozzle -> time of flight on the parabola y = -(kVy t + g t^2 / 2).
        const float depth = (static_cast<float>(slice) + 0.5f) * kStreamRadius;
        const float t = (-kVy + std::sqrt(kVy * kVy + 2.0f * kGravity * depth)) / kGravity;
        const float cx = static_cast<float>(stream % grid) * kPitch + kVx * t;
        const float cz = static_cast<float>(stream / grid) * kPitch;
        const float rot =
            2.0f * std::numbers::pi_v<float> * counter_uniform(kSeed, 1, stream * slices + slice, 0);
        const float rr = disk * std::sqrt((static_cast<float>(k) + 0.5f) / static_cast<float>(per_slice));
        const float a = rot + kGolden * static_cast<float>(k);
        const float j = 0.25f * kStreamRadius;
        set.push(cx + rr * std::cos(a) + j * uniform(i, 1), kDrop - depth + j * uniform(i, 2),
                 cz + rr * std::sin(a) + j * uniform(i, 3), 0, 0, 0, static_cast<std::uint32_t>(i));
    }
    return set;
}

}  // namespace rivulet::perf
