#include "systems/sim/stream_sim.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "jobs/counter_rng.h"
#include "systems/sim/height_field_pool.h"

namespace rivulet {

namespace {

constexpr std::uint32_t kMaxParticles = 50'000'000;
// Particles this far from the origin are lost to the scene whatever it is; recycling them keeps stray
// ones from living out their lifetime far off-screen.
constexpr float kWorldHalfExtent = 1000.0f;
constexpr float kRestSpeed = 0.2f;  // m/s: slower than this on the ground counts as resting

// Random streams of one emitted particle (counter_uniform's last argument).
enum : std::uint64_t { kDiskRadius = 0, kDiskAngle = 1, kConeCos = 2, kConeAngle = 3 };

bool finite(Vec3f v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

void validate(const SceneDesc& s) {
    const auto check = [&](bool ok, const char* what) {
        if (!ok) throw std::invalid_argument("scene '" + s.name + "': " + what);
    };
    check(std::isfinite(s.dt) && s.dt > 0 && s.dt <= 1, "dt must be in (0, 1]");
    check(s.substeps >= 1 && s.substeps <= 64, "substeps must be in [1, 64]");
    check(s.max_particles >= 1 && s.max_particles <= kMaxParticles, "max_particles must be in [1, 50000000]");
    check(std::isfinite(s.particle_radius) && s.particle_radius > 0, "particle_radius must be positive");
    check(std::isfinite(s.lifetime) && s.lifetime > 0, "lifetime must be positive");
    check(s.warmup_frames >= 0, "warmup_frames must be >= 0");
    check(finite(s.gravity) && std::isfinite(s.ground_y), "gravity and ground_y must be finite");
    check(std::isfinite(s.restitution) && s.restitution >= 0 && s.restitution <= 1,
          "restitution must be in [0, 1]");
    check(std::isfinite(s.friction) && s.friction >= 0 && s.friction <= 1, "friction must be in [0, 1]");
    check(std::isfinite(s.v_min) && std::isfinite(s.v_max) && s.v_min < s.v_max, "need finite v_min < v_max");
    check(finite(s.camera.eye) && finite(s.camera.target) && std::isfinite(s.camera.fov_y_deg) &&
              s.camera.fov_y_deg > 0 && s.camera.fov_y_deg < 180,
          "camera must be finite with fov_y_deg in (0, 180)");
    for (const Emitter& e : s.emitters) {
        check(finite(e.position) && finite(e.direction) && dot(e.direction, e.direction) > 0,
              "emitter needs a finite position and a non-zero direction");
        check(std::isfinite(e.speed) && std::isfinite(e.spread) && std::isfinite(e.nozzle_radius),
              "emitter values must be finite");
        check(e.spread >= 0 && e.spread <= std::numbers::pi_v<float> && e.nozzle_radius >= 0,
              "emitter spread must be in [0, pi] and nozzle_radius >= 0");
        check(std::isfinite(e.rate) && e.rate >= 0 && e.rate <= 1e9f, "emitter rate must be in [0, 1e9]");
    }
    for (const SphereCollider& c : s.spheres) {
        check(finite(c.center) && std::isfinite(c.radius) && c.radius >= 0, "sphere collider invalid");
    }
    for (const BoxCollider& b : s.boxes) {
        check(
            finite(b.min) && finite(b.max) && b.min.x <= b.max.x && b.min.y <= b.max.y && b.min.z <= b.max.z,
            "box collider needs finite min <= max");
    }
    check(s.pool.nx >= 2 && s.pool.nx <= 4096 && s.pool.nz >= 2 && s.pool.nz <= 4096,
          "pool nx, nz must be in [2, 4096]");
}

}  // namespace

StreamSimulation::StreamSimulation(const SceneDesc& scene) : scene_(scene) {
    validate(scene_);
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
