#include "systems/sim/stream_sim.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "jobs/counter_rng.h"
#include "systems/scenes/scene_validation.h"
#include "systems/sim/height_field_pool.h"

namespace rivulet {

namespace {

// Particles this far from the origin are lost to the scene whatever it is; recycling them keeps stray
// ones from living out their lifetime far off-screen.
constexpr float kWorldHalfExtent = 1000.0f;
constexpr float kRestSpeed = 0.2f;  // m/s: slower than this on the ground counts as resting

// Random streams of one emitted particle (counter_uniform's last argument).
enum : std::uint64_t { kDiskRadius = 0, kDiskAngle = 1, kConeCos = 2, kConeAngle = 3 };

}  // namespace

StreamSimulation::StreamSimulation(const SceneDesc& scene) : scene_(scene) {
    validate_scene(scene_);
    if (scene_.pool.enabled) pool_ = std::make_unique<HeightFieldPool>(scene_.pool, scene_.dt);

    carry_.assign(scene_.emitters.size(), 0.0);
    for (const Emitter& e : scene_.emitters) {
        const Vec3f axis = normalize(e.direction);
        const Vec3f helper = std::abs(axis.y) < 0.9f ? Vec3f{0, 1, 0} : Vec3f{1, 0, 0};
        const Vec3f side = normalize(cross(helper, axis));
        frames_.push_back({axis, side, cross(axis, side)});
    }
    for (const SphereCollider& c : scene_.spheres) spheres_.push_back({c.center, c.radius});
    for (const BoxCollider& b : scene_.boxes) boxes_.push_back({b.min, b.max});

    const std::size_t n = scene_.max_particles;
    birth_.reserve(n), fate_.reserve(n), hit_x_.reserve(n), hit_z_.reserve(n), hit_momentum_.reserve(n);
    std::fill_n(birth_.data(), n, 0u);
    std::fill_n(fate_.data(), n, std::uint8_t{kAlive});

    params_.gravity = scene_.gravity;
    params_.dt = scene_.dt;
    params_.substeps = scene_.substeps;
    params_.radius = scene_.particle_radius;
    params_.ground_y = scene_.ground_y;
    params_.restitution = scene_.restitution;
    params_.friction = scene_.friction;
    params_.spheres = spheres_;
    params_.boxes = boxes_;
    params_.rest_speed = kRestSpeed;
    const float reach = kWorldHalfExtent + std::abs(scene_.ground_y);
    params_.bounds_min = {-reach, -reach, -reach};
    params_.bounds_max = {reach, reach, reach};
    const double frames = std::ceil(double(scene_.lifetime) / scene_.dt);
    params_.max_age = static_cast<std::uint32_t>(std::clamp(frames, 1.0, 4e9));
    if (pool_) {
        const HeightFieldView v = pool_->view();
        params_.surface = {v.nx, v.nz, v.x0, v.z0, v.dx, v.dz, v.heights.data()};
    }
}

StreamSimulation::~StreamSimulation() = default;

void StreamSimulation::begin_frame(ParticleSet& particles, std::uint64_t frame) {
    if (particles.size() > scene_.max_particles) {
        throw std::length_error("StreamSimulation: particle set holds more than scene.max_particles");
    }
    // Particles added by someone else are treated as born now.
    for (std::size_t i = stamped_; i < particles.size(); ++i) birth_[i] = tick_;

    const std::size_t limit = std::min<std::size_t>(particles.capacity(), scene_.max_particles);
    const std::uint64_t seed = scene_.seed;
    const float two_pi = 2.0f * std::numbers::pi_v<float>;
    for (std::size_t k = 0; k < scene_.emitters.size(); ++k) {
        const Emitter& e = scene_.emitters[k];
        const EmitterFrame& f = frames_[k];
        const double rate = double(e.rate) * double(emitter_scale_);
        const double owed = carry_[k] + rate * scene_.dt;
        const double whole = std::floor(owed);
        const double carried = carry_[k];
        carry_[k] = owed - whole;
        const std::size_t room = limit - particles.size();
        const std::size_t count = static_cast<std::size_t>(std::min(whole, double(room)));
        const float cos_spread = std::cos(e.spread);
        for (std::size_t j = 0; j < count; ++j) {
            const std::uint32_t id = next_id_++;
            const float disk_r = e.nozzle_radius * std::sqrt(counter_uniform(seed, frame, id, kDiskRadius));
            const float disk_a = two_pi * counter_uniform(seed, frame, id, kDiskAngle);
            const float cos_t = 1.0f - counter_uniform(seed, frame, id, kConeCos) * (1.0f - cos_spread);
            const float sin_t = std::sqrt(std::max(0.0f, 1.0f - cos_t * cos_t));
            const float cone_a = two_pi * counter_uniform(seed, frame, id, kConeAngle);
            const Vec3f p0 =
                e.position + f.side * (disk_r * std::cos(disk_a)) + f.up * (disk_r * std::sin(disk_a));
            const Vec3f dir =
                f.axis * cos_t + f.side * (sin_t * std::cos(cone_a)) + f.up * (sin_t * std::sin(cone_a));
            const Vec3f v0 = dir * e.speed;
            // Emission is continuous: the j-th particle of this frame left the nozzle when the emitter's
            // running count crossed its number, so streams come out evenly spaced rather than in clumps.
            const float age = static_cast<float>(scene_.dt - (double(j) + 1.0 - carried) / rate);
            const Vec3f p = p0 + v0 * age + scene_.gravity * (0.5f * age * age);
            const Vec3f v = v0 + scene_.gravity * age;
            birth_[particles.size()] = tick_;
            particles.push(p.x, p.y, p.z, v.x, v.y, v.z, id);
        }
    }
    stamped_ = particles.size();
    std::fill_n(fate_.data(), particles.size(), std::uint8_t{kAlive});
}

void StreamSimulation::integrate(ParticleSet& particles, std::size_t begin, std::size_t end) {
    end = std::min(end, particles.size());
    if (begin >= end) return;
    BallisticParams params = params_;
    params.now = tick_;
    const std::size_t n = particles.size();
    const BallisticOutputs out{fate_.span(n), hit_x_.span(n), hit_z_.span(n), hit_momentum_.span(n)};
    ballistic_step(particles.spans(), birth_.span(n), begin, end, params, out);
}

void StreamSimulation::end_frame(ParticleSet& particles) {
    const std::size_t n = particles.size();
    std::size_t survivors = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint8_t fate = fate_[i];
        if (fate == kAbsorbed && pool_) pool_->apply_impulse(hit_x_[i], hit_z_[i], hit_momentum_[i]);
        if (fate == kAlive) birth_[survivors++] = birth_[i];
    }
    if (survivors != n) particles.remove_flagged(fate_.data());
    stamped_ = particles.size();
    if (pool_) pool_->step();
    ++tick_;
}

void StreamSimulation::step_serial(ParticleSet& particles, std::uint64_t frame) {
    begin_frame(particles, frame);
    integrate(particles, 0, particles.size());
    end_frame(particles);
}

void StreamSimulation::set_inputs(const FrameInputs& inputs) {
    if (!std::isfinite(inputs.emitter_scale) || inputs.emitter_scale < 0 || inputs.emitter_scale > 1e3f)
        throw std::invalid_argument("StreamSimulation: emitter_scale must be in [0, 1000]");
    emitter_scale_ = inputs.emitter_scale;
}

HeightFieldView StreamSimulation::pool_view() const {
    return pool_ ? pool_->view() : HeightFieldView{};
}

}  // namespace rivulet
