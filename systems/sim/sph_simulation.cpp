#include "systems/sim/sph_simulation.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace rivulet {

namespace {

// Lattice points (spacing d) of a box: min + (i + 1/2) d along each axis, as many as fit.
int lattice_count(float lo, float hi, float d) {
    const float n = std::floor((hi - lo) / d + 1e-3f);
    return n > 0.0f ? static_cast<int>(n) : 0;
}

template <class F>
void for_each_seed(const SphDesc& desc, F&& f) {
    const float d = desc.spacing;
    for (const SphFluidBox& b : desc.fluid_boxes) {
        const int nx = lattice_count(b.min.x, b.max.x, d);
        const int ny = lattice_count(b.min.y, b.max.y, d);
        const int nz = lattice_count(b.min.z, b.max.z, d);
        for (int k = 0; k < nz; ++k) {
            for (int j = 0; j < ny; ++j) {
                for (int i = 0; i < nx; ++i) {
                    const Vec3f p{b.min.x + (static_cast<float>(i) + 0.5f) * d,
                                  b.min.y + (static_cast<float>(j) + 0.5f) * d,
                                  b.min.z + (static_cast<float>(k) + 0.5f) * d};
                    f(p, b.velocity);
                }
            }
        }
    }
    for (const SphFluidSphere& s : desc.fluid_spheres) {
        const int r = static_cast<int>(std::floor(s.radius / d));
        const float r2 = s.radius * s.radius;
        for (int k = -r; k <= r; ++k) {
            for (int j = -r; j <= r; ++j) {
                for (int i = -r; i <= r; ++i) {
                    const Vec3f o{static_cast<float>(i) * d, static_cast<float>(j) * d,
                                  static_cast<float>(k) * d};
                    if (dot(o, o) <= r2) f(s.center + o, s.velocity);
                }
            }
        }
    }
}

// Mass that makes the poly6 density of an unbounded cubic lattice of spacing d equal rho0.
float lattice_mass(const SphKernels& k, float d, float rho0) {
    const int reach = static_cast<int>(std::ceil(k.h / d));
    double sum = 0;
    for (int z = -reach; z <= reach; ++z) {
        for (int y = -reach; y <= reach; ++y) {
            for (int x = -reach; x <= reach; ++x) {
                const double r2 = (double(x) * x + double(y) * y + double(z) * z) * double(d) * d;
                const double q = double(k.h2) - r2;
                if (q > 0) sum += q * q * q;
            }
        }
    }
    return static_cast<float>(double(rho0) / (double(k.poly6) * sum));
}

}  // namespace

std::size_t sph_seed_count(const SphDesc& desc) {
    std::size_t n = 0;
    for_each_seed(desc, [&](Vec3f, Vec3f) { ++n; });
    return n;
}

SphSimulation::SphSimulation(const SphDesc& desc, std::size_t max_particles, std::size_t chunks)
    : desc_(desc),
      max_particles_(max_particles),
      chunks_(chunks > 0 ? chunks : std::clamp<std::size_t>((max_particles + 4095) / 4096, 1, 32)) {
    const float d = desc.spacing;
    const BoxCollider& box = desc.container.box;
    if (!(d > 0.0f) || !(desc.support_ratio >= 1.0f) || !(desc.rest_density > 0.0f) ||
        !(desc.sound_speed > 0.0f) || !(desc.gamma >= 1.0f) || !(desc.viscosity >= 0.0f) ||
        !(desc.dt > 0.0f) || !(desc.cfl > 0.0f) || desc.max_substeps < 1 || !(box.max.x > box.min.x) ||
        !(box.max.y > box.min.y) || !(box.max.z > box.min.z)) {
        throw std::invalid_argument(
            "SphDesc: spacing, support_ratio >= 1, rest density, sound speed, gamma "
            ">= 1, viscosity >= 0, dt, cfl, max_substeps >= 1 and a non-empty tank");
    }
    const float h = desc.support();
    fluid_.kernels = SphKernels(h);
    fluid_.rest_density = desc.rest_density;
    fluid_.mass = lattice_mass(fluid_.kernels, d, desc.rest_density);
    fluid_.gamma = desc.gamma;
    fluid_.stiffness = desc.rest_density * desc.sound_speed * desc.sound_speed / desc.gamma;
    fluid_.viscosity = desc.viscosity;
    fluid_.alpha = desc.artificial_viscosity;
    fluid_.sound_speed = desc.sound_speed;
    fluid_.surface_tension = desc.surface_tension;
    fluid_.tension = desc.tension;
    fluid_.tension_threshold = desc.tension_threshold;
    fluid_.gx = desc.gravity.x, fluid_.gy = desc.gravity.y, fluid_.gz = desc.gravity.z;

    // Cells h wide over the tank plus one cell all round (particles outside go to border cells).
    const Vec3f size = box.max - box.min;
    auto cells_along = [h](float s) {
        const double n = std::ceil(double(s) / h) + 2.0;
        if (n > 4096.0) throw std::invalid_argument("SphDesc: tank over 4096 cells along an axis");
        return static_cast<std::uint32_t>(n);
    };
    grid_.cell = h;
    grid_.nx = cells_along(size.x), grid_.ny = cells_along(size.y), grid_.nz = cells_along(size.z);
    const std::size_t cells = grid_.cells();
    if (cells > (std::size_t(1) << 28)) throw std::invalid_argument("SphDesc: grid over 2^28 cells");

    for (const SphereCollider& s : desc.spheres) spheres_.push_back({s.center, s.radius});
    for (const BoxCollider& b : desc.boxes) boxes_.push_back({b.min, b.max});
    boundary_.spheres = spheres_;
    boundary_.boxes = boxes_;
    boundary_.margin = 0.5f * d;
    walls_.enabled = desc.wall_pressure;

    const std::size_t n = std::max<std::size_t>(max_particles, 1);
    keys_.reserve(n);
    counts_.reserve(chunks_ * cells);
    cursors_.reserve(chunks_ * cells);
    cell_start_.reserve(cells + 1);
    cell_total_.reserve(cells);
    for (auto* a : {&sx_, &sy_, &sz_, &svx_, &svy_, &svz_, &rho_, &p_, &ax_, &ay_, &az_}) a->reserve(n);
    sid_.reserve(n);
    skey_.reserve(n);
    chunk_a2_.reserve(chunks_);
    chunk_v2_.reserve(chunks_);
    for (std::size_t c = 0; c < chunks_; ++c) chunk_a2_[c] = 0, chunk_v2_[c] = 0;
}

Vec3f SphSimulation::scripted_offset(double t) const {
    const SphContainer& c = desc_.container;
    const double s = double(c.amplitude) * std::sin(2.0 * std::numbers::pi * double(c.frequency) * t);
    return user_offset_ + c.axis * static_cast<float>(s);
}

BoxCollider SphSimulation::tank() const {
    const BoxCollider& b = desc_.container.box;
    return {b.min + offset_now_, b.max + offset_now_};
}

void SphSimulation::seed(ParticleSet& ps) {
    const std::size_t count = sph_seed_count(desc_);
    if (count > max_particles_)
        throw std::length_error("SphSimulation::seed: more particles than max_particles");
    if (count > ps.capacity()) ps.reserve(count);
    ps.clear();
    std::uint32_t id = 0;
    for_each_seed(desc_, [&](Vec3f p, Vec3f v) { ps.push(p.x, p.y, p.z, v.x, v.y, v.z, id++); });
    n_ = ps.size();
    time_ = 0;
    substeps_ = 1;
    substep_ = 0;
    offset_begin_ = offset_end_ = offset_now_ = scripted_offset(0.0);
    for (std::size_t c = 0; c < chunks_; ++c) chunk_a2_[c] = 0, chunk_v2_[c] = 0;
    for (std::size_t i = 0; i < n_; ++i) rho_[i] = desc_.rest_density, p_[i] = 0;
}

int SphSimulation::begin_frame(ParticleSet& ps, std::uint64_t frame) {
    if (ps.size() != n_) throw std::logic_error("SphSimulation: particle count changed since seed()");
    const double frame_dt = desc_.dt;
    offset_begin_ = offset_now_;
    offset_end_ = scripted_offset(double(frame + 1) * frame_dt);

    // Step limits from the current state: speed (CFL on c0 + |v|max), acceleration of the last substep,
    // viscosity.
    float v2 = 0;
    const auto vx = ps.vx(), vy = ps.vy(), vz = ps.vz();
    for (std::size_t i = 0; i < n_; ++i) v2 = std::max(v2, vx[i] * vx[i] + vy[i] * vy[i] + vz[i] * vz[i]);
    const Vec3f wall_v = (offset_end_ - offset_begin_) * static_cast<float>(1.0 / frame_dt);
    const double vmax = std::sqrt(double(v2)) + double(length(wall_v));
    float a2 = dot(desc_.gravity, desc_.gravity);
    for (std::size_t c = 0; c < chunks_; ++c) a2 = std::max(a2, chunk_a2_[c]);
    const double h = fluid_.kernels.h;
    double limit = double(desc_.cfl) * h / (double(desc_.sound_speed) + vmax);
    if (a2 > 0) limit = std::min(limit, 0.25 * std::sqrt(h / std::sqrt(double(a2))));
    if (desc_.viscosity > 0) limit = std::min(limit, 0.125 * h * h * desc_.rest_density / desc_.viscosity);
    const double wanted = std::ceil(frame_dt / limit - 1e-9);
    substeps_ = static_cast<int>(std::clamp(wanted, 1.0, double(desc_.max_substeps)));
    dt_sub_ = static_cast<float>(frame_dt / substeps_);
    substep_ = 0;
    return substeps_;
}

SphNeighbourhood SphSimulation::neighbourhood() const {
    return {grid_,       cell_start_.span(grid_.cells() + 1), skey_.span(n_), sx_.span(n_), sy_.span(n_),
            sz_.span(n_)};
}

void SphSimulation::run_phase(std::size_t phase, std::size_t chunk, ParticleSet& ps) {
    const std::size_t b = chunk_begin(chunk), e = chunk_begin(chunk + 1);
    const std::uint32_t cells = grid_.cells();
    switch (phase) {
        case kSubstep: {
            // The container moves linearly over the frame; this substep ends at fraction (s + 1) / S.
            const float f = static_cast<float>(substep_ + 1) / static_cast<float>(substeps_);
            const Vec3f before = offset_now_;
            offset_now_ = offset_begin_ + (offset_end_ - offset_begin_) * f;
            const BoxCollider t = tank();
            boundary_.tank_min = t.min, boundary_.tank_max = t.max;
            // The fluid sees the walls where they are at the start of the substep.
            const Vec3f w0 = desc_.container.box.min + before, w1 = desc_.container.box.max + before;
            walls_.min[0] = w0.x, walls_.min[1] = w0.y, walls_.min[2] = w0.z;
            walls_.max[0] = w1.x, walls_.max[1] = w1.y, walls_.max[2] = w1.z;
            boundary_.tank_velocity = (offset_now_ - before) * (1.0f / dt_sub_);
            const Vec3f wv = boundary_.tank_velocity;
            walls_.velocity[0] = wv.x, walls_.velocity[1] = wv.y, walls_.velocity[2] = wv.z;
            // The grid follows the tank at the start of the substep, one cell of slack all round.
            const float h = grid_.cell;
            grid_.origin = desc_.container.box.min + before - Vec3f{h, h, h};
            ++substep_;
            break;
        }
        case kGridCount: {
            const auto x = ps.x(), y = ps.y(), z = ps.z();
            sph_grid_count_chunk(grid_, x.subspan(b, e - b), y.subspan(b, e - b), z.subspan(b, e - b),
                                 keys_.span(n_).subspan(b, e - b),
                                 counts_.span(chunks_ * cells).subspan(chunk * cells, cells));
            break;
        }
        case kGridCursors: {
            const auto first = static_cast<std::uint32_t>(std::size_t(chunk) * cells / chunks_);
            const auto last = static_cast<std::uint32_t>(std::size_t(chunk + 1) * cells / chunks_);
            sph_grid_cursors(cells, static_cast<std::uint32_t>(chunks_), first, last,
                             counts_.span(chunks_ * cells), cursors_.span(chunks_ * cells),
                             cell_total_.span(cells));
            break;
        }
        case kGridOffsets:
            sph_grid_offsets(cell_total_.span(cells), cell_start_.span(cells + 1));
            break;
        case kGridScatter: {
            const SphParticlesIn in{ps.x().subspan(b, e - b),  ps.y().subspan(b, e - b),
                                    ps.z().subspan(b, e - b),  ps.vx().subspan(b, e - b),
                                    ps.vy().subspan(b, e - b), ps.vz().subspan(b, e - b),
                                    ps.id().subspan(b, e - b)};
            const SphSortedOut out{sx_.span(n_),  sy_.span(n_),  sz_.span(n_),  svx_.span(n_),
                                   svy_.span(n_), svz_.span(n_), sid_.span(n_), skey_.span(n_)};
            sph_grid_scatter_chunk(in, keys_.span(n_).subspan(b, e - b), cell_start_.span(cells + 1),
                                   cursors_.span(chunks_ * cells).subspan(chunk * cells, cells), out);
            break;
        }
        case kDensity:
            sph_density(neighbourhood(), fluid_, walls_, b, e, rho_.span(n_), p_.span(n_));
            break;
        case kForces: {
            const SphForceInputs in{neighbourhood(), svx_.span(n_), svy_.span(n_),
                                    svz_.span(n_),   rho_.span(n_), p_.span(n_)};
            chunk_a2_[chunk] =
                sph_forces(in, fluid_, walls_, b, e, {ax_.span(n_), ay_.span(n_), az_.span(n_)});
            break;
        }
        case kIntegrate: {
            const SphParticlesIn in{sx_.span(n_),  sy_.span(n_),  sz_.span(n_), svx_.span(n_),
                                    svy_.span(n_), svz_.span(n_), sid_.span(n_)};
            chunk_v2_[chunk] = sph_integrate(in, {ax_.span(n_), ay_.span(n_), az_.span(n_)}, b, e, dt_sub_,
                                             boundary_, ps.spans());
            break;
        }
        default:
            throw std::out_of_range("SphSimulation::run_phase: no such phase");
    }
}

void SphSimulation::end_frame(ParticleSet&) {
    time_ += desc_.dt;
}

void SphSimulation::step_serial(ParticleSet& ps, std::uint64_t frame) {
    const int substeps = begin_frame(ps, frame);
    for (int s = 0; s < substeps; ++s) {
        for (std::size_t p = 0; p < kPhaseCount; ++p) {
            const std::size_t n = kPhases[p].parallel ? chunks_ : 1;
            for (std::size_t c = 0; c < n; ++c) run_phase(p, c, ps);
        }
    }
    end_frame(ps);
}

void SphSimulation::step_parallel(ParticleSet& ps, std::uint64_t frame) {
    const int substeps = begin_frame(ps, frame);
    for (int s = 0; s < substeps; ++s) {
        for (std::size_t p = 0; p < kPhaseCount; ++p) {
            if (!kPhases[p].parallel) {
                run_phase(p, 0, ps);
                continue;
            }
            tbb::parallel_for(
                tbb::blocked_range<std::size_t>(0, chunks_, 1),
                [&](const tbb::blocked_range<std::size_t>& r) {
                    for (std::size_t c = r.begin(); c != r.end(); ++c) run_phase(p, c, ps);
                },
                tbb::simple_partitioner());
        }
    }
    end_frame(ps);
}

}  // namespace rivulet
