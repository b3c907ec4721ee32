#include "systems/sim/sph_simulation.h"

#include "systems/io/text_parse.h"
#include "systems/scenes/scene_limits.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

namespace rivulet {

namespace {

// Lattice points (spacing d) of a box: min + (i + 1/2) d along each axis, as many as fit. Only called
// once sph_seed_count has shown the whole lattice is small.
int lattice_count(float lo, float hi, float d) {
    const float n = std::floor((hi - lo) / d + 1e-3f);
    return n > 0.0f ? static_cast<int>(n) : 0;
}

// Any count above this is as good as infinite: no scene may hold that many particles.
constexpr std::size_t kCountSaturation = std::size_t{kMaxSceneParticles} + 1;

std::size_t saturating_add(std::size_t a, std::size_t b) {
    return std::min(a + std::min(b, kCountSaturation), kCountSaturation);
}

// lattice_count without the int: a tiny spacing gives a huge float, not an overflow.
double lattice_extent(float lo, float hi, float d) {
    const float n = std::floor((hi - lo) / d + 1e-3f);
    return n > 0.0f ? static_cast<double>(n) : 0.0;
}

std::size_t box_seed_count(const SphFluidBox& b, float d) {
    const double n = lattice_extent(b.min.x, b.max.x, d) * lattice_extent(b.min.y, b.max.y, d) *
                     lattice_extent(b.min.z, b.max.z, d);
    return n >= double(kCountSaturation) ? kCountSaturation : static_cast<std::size_t>(n);
}

// The points for_each_seed places in a sphere, counted row by row: along a row the test
// dot(o, o) <= r^2 holds for |i| up to some m (float rounding is monotone), found by bisection.
std::size_t sphere_seed_count(const SphFluidSphere& s, float d) {
    const float reach = std::floor(s.radius / d);
    // The cube inscribed in a sphere of r lattice steps holds (2 floor(r / sqrt 3) + 1)^3 points, over
    // kMaxSceneParticles from r = 400 on: larger spheres need not be counted.
    if (!(reach <= 512.0f)) return kCountSaturation;
    const int r = static_cast<int>(reach);
    const float r2 = s.radius * s.radius;
    const auto inside = [d, r2](int i, int j, int k) {
        const Vec3f o{static_cast<float>(i) * d, static_cast<float>(j) * d, static_cast<float>(k) * d};
        return dot(o, o) <= r2;
    };
    std::size_t n = 0;
    for (int k = -r; k <= r; ++k) {
        for (int j = -r; j <= r; ++j) {
            if (!inside(0, j, k)) continue;
            int lo = 0, hi = r;  // inside(lo) holds; find the largest such lo
            while (lo < hi) {
                const int mid = lo + (hi - lo + 1) / 2;
                if (inside(mid, j, k)) {
                    lo = mid;
                } else {
                    hi = mid - 1;
                }
            }
            n += 2 * static_cast<std::size_t>(lo) + 1;
        }
    }
    return n;
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
    const float d = desc.spacing;
    if (!(d > 0.0f)) return kCountSaturation;
    std::size_t n = 0;
    for (const SphFluidBox& b : desc.fluid_boxes) n = saturating_add(n, box_seed_count(b, d));
    for (const SphFluidSphere& s : desc.fluid_spheres) n = saturating_add(n, sphere_seed_count(s, d));
    return n;
}

namespace {

// Pairs first reserved per particle for the DFSPH lists: a particle inside the fluid at rest has 26 to 32
// neighbours at support 2 spacings, padded to a multiple of four; the lists grow (once) where that is not
// enough.
constexpr std::uint64_t kListPairs = 40;
// The density error a substep starts with is removed over at least this time (s).
constexpr float kDensityCatchUp = 0.004f;
// Share of the last substep's summed stiffness the divergence solve starts from (1 overshoots: the
// stiffness of a substep includes its own error's correction, which the next one does not need again).
constexpr float kWarmStartShare = 0.8f;
// The density solve starts from this share of the smaller of the last two substeps' stiffness. What a
// substep needs again is the steady part (the pressure that holds the fluid up against gravity), which
// both have; an impact's stiffness stops the fluid once, and the velocity it gave persists, so starting
// from the last substep alone pushes the stopped fluid out again, and a solve that ends at its first look
// never takes that back (its test counts compression only, averaged over every particle): the fluid
// gains energy at every wall impact (test DfsphEnergyTest). 1.0 adds some again.
constexpr float kDensityWarmShare = 0.9f;

// One chunk per 512 particles: at 2 threads a phase's last chunk leaves the other thread idle for about
// half a chunk, and at 1,024 a chunk that cost the 24k dam break 3 % (each chunk's fixed cost is 1.5 % at
// 1 thread). The bytes do not depend on the cut.
std::size_t default_chunks(std::size_t max_particles) {
    return std::clamp<std::size_t>((max_particles + 511) / 512, 1, 64);
}

// Cells h wide over the tank plus one cell all round (particles outside go to border cells); 0 when an
// axis would need more than kMaxGridCellsPerAxis.
std::uint32_t cells_along(float extent, float h) {
    const double n = std::ceil(double(extent) / double(h)) + 2.0;
    return n <= double(kMaxGridCellsPerAxis) ? static_cast<std::uint32_t>(n) : 0;
}

}  // namespace

double sph_max_tank_speed(const SphDesc& desc) {
    return double(desc.step_cfl()) * double(desc.spacing) * double(desc.max_substeps) / double(desc.dt);
}

std::string sph_desc_problem(const SphDesc& d, std::size_t max_particles) {
    using io::number_text;
    constexpr double kHuge = 1e30;  // no upper bound but finiteness
    const auto range = [](const char* key, double v, double lo, double hi, bool open_lo = false) {
        if (std::isfinite(v) && (open_lo ? v > lo : v >= lo) && v <= hi) return std::string();
        const std::string want =
            hi == kHuge ? std::string(" finite and ") + (open_lo ? "> " : ">= ") + number_text(lo)
                        : std::string(" in ") + (open_lo ? "(" : "[") + number_text(lo) + ", " +
                              number_text(hi) + "]";
        return std::string(key) + " must be" + want + ", got " + number_text(v);
    };
    for (const std::string& problem :
         {range("sph.spacing", d.spacing, 0, 1e3, true), range("sph.support_ratio", d.support_ratio, 1, 8),
          range("sph.rest_density", d.rest_density, 0, kHuge, true),
          range("sph.sound_speed", d.sound_speed, 0, kHuge, true), range("sph.gamma", d.gamma, 1, 100),
          range("sph.viscosity", d.viscosity, 0, kHuge),
          range("sph.artificial_viscosity", d.artificial_viscosity, 0, kHuge),
          range("sph.tension", d.tension, 0, kHuge),
          range("sph.tension_threshold", d.tension_threshold, 0, kHuge), range("dt", d.dt, 0, 1, true),
          range("sph.cfl", d.cfl, 0, 10), range("sph.max_substeps", d.max_substeps, 1, kMaxSphSubsteps),
          range("sph.max_density_error", d.max_density_error, 0, 100, true),
          range("sph.max_divergence_error", d.max_divergence_error, 0, 100, true),
          range("sph.max_iterations", d.max_iterations, 1, 10000),
          range("sph.chebyshev", d.chebyshev, 0, 0.99)})
        if (!problem.empty()) return problem;
    const BoxCollider& box = d.container.box;
    if (!finite(box.min) || !finite(box.max) || !(box.max.x > box.min.x) || !(box.max.y > box.min.y) ||
        !(box.max.z > box.min.z))
        return "sph.container.box needs finite min < max on every axis";
    if (!finite(d.container.axis) || !std::isfinite(d.container.amplitude) ||
        !std::isfinite(d.container.frequency) || !finite(d.gravity))
        return "the container's motion and gravity must be finite";
    for (const SphFluidBox& b : d.fluid_boxes)
        if (!finite(b.min) || !finite(b.max) || !finite(b.velocity))
            return "sph.fluid_boxes need finite min, max and velocity";
    for (const SphFluidSphere& s : d.fluid_spheres)
        if (!finite(s.center) || !finite(s.velocity) || !std::isfinite(s.radius) || s.radius < 0)
            return "sph.fluid_spheres need a finite center and velocity and a radius >= 0";

    // The grid before the lattice: a spacing far too small for the tank is named as such.
    const float h = d.support();
    const Vec3f size = box.max - box.min;
    const std::uint32_t n[3] = {cells_along(size.x, h), cells_along(size.y, h), cells_along(size.z, h)};
    for (int a = 0; a < 3; ++a)
        if (n[a] == 0)
            return "the tank is " + number_text(double((&size.x)[a]) / h) + " kernel radii along " +
                   "xyz"[a] + " (limit " + std::to_string(kMaxGridCellsPerAxis - 2) +
                   "): sph.spacing is too small for sph.container.box";
    const std::uint64_t cells = std::uint64_t{n[0]} * n[1] * n[2];
    if (cells > kMaxGridCells)
        return "the tank needs " + std::to_string(cells) + " grid cells (limit " +
               std::to_string(kMaxGridCells) + "): sph.spacing is too small for sph.container.box";

    const std::size_t seeds = sph_seed_count(d);
    if (seeds == 0) return "its SPH fluid holds no particles";
    if (seeds > max_particles)
        return "its SPH fluid needs " +
               (seeds > kMaxSceneParticles ? "more than " + std::to_string(kMaxSceneParticles)
                                           : std::to_string(seeds)) +
               " particles but max_particles is " + std::to_string(max_particles);
    const std::uint64_t bytes = sph_buffer_bytes(cells, max_particles);
    if (bytes > kMaxSimulationBytes)
        return "its SPH buffers would take " + io::bytes_text(bytes) + " (" + std::to_string(max_particles) +
               " particles, " + std::to_string(cells) + " grid cells), over the " +
               io::bytes_text(kMaxSimulationBytes) + " limit";
    return {};
}

std::uint64_t sph_buffer_bytes(std::uint64_t cells, std::size_t max_particles) {
    const std::uint64_t n = std::max<std::size_t>(max_particles, 1);
    // 11 float columns, ids, sorted keys, store-order keys; counts and cursors per chunk and cell; starts
    // and totals per cell. DFSPH: 2 list indices and 15 floats per particle (8 of them the packed
    // velocities and positions), and the lists as first reserved (kListPairs pairs per particle).
    return n * 14 * 4 + (2 * default_chunks(max_particles) + 2) * cells * 4 +
           n * (17 * 4 + kListPairs * sizeof(DfsphPair));
}

SphSimulation::SphSimulation(const SphDesc& desc, std::size_t max_particles, std::size_t chunks)
    : desc_(desc),
      max_particles_(max_particles),
      chunks_(chunks > 0 ? chunks : default_chunks(max_particles)) {
    if (const std::string problem = sph_desc_problem(desc, max_particles); !problem.empty())
        throw std::invalid_argument("SphDesc: " + problem);
    const float d = desc.spacing;
    const BoxCollider& box = desc.container.box;
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

    const Vec3f size = box.max - box.min;
    grid_.cell = h;
    grid_.nx = cells_along(size.x, h), grid_.ny = cells_along(size.y, h), grid_.nz = cells_along(size.z, h);
    const std::size_t cells = grid_.cells();

    for (const SphereCollider& s : desc.spheres) spheres_.push_back({s.center, s.radius});
    for (const BoxCollider& b : desc.boxes) boxes_.push_back({b.min, b.max});
    boundary_.spheres = spheres_;
    boundary_.boxes = boxes_;
    // WCSPH keeps particles half a spacing from every surface. DFSPH's walls hold the fluid by its density
    // (the wall's share B), and a particle stopped short of where the solver moved it breaks the density
    // the solver predicted, so there the contact only catches particles that reach the wall.
    boundary_.margin = (desc.solver == SphSolver::kDfsph ? 0.1f : 0.5f) * d;
    walls_.enabled = desc.wall_pressure;

    cubic_ = SphCubicKernel(h);
    volume_ = dfsph_lattice_volume(cubic_, d);
    wall_table_ = DfsphWallTable(cubic_, volume_, d);
    if (desc.solver == SphSolver::kDfsph) fluid_.mass = desc.rest_density * volume_;
    full_neighbours_ = static_cast<float>(dfsph_lattice_neighbours(cubic_, d));

    const std::size_t n = std::max<std::size_t>(max_particles, 1);
    keys_.reserve(n);
    counts_.reserve(chunks_ * cells);
    cursors_.reserve(chunks_ * cells);
    key_ranges_.assign(chunks_, SphKeyRange{});
    cell_start_.reserve(cells + 1);
    cell_total_.reserve(cells);
    for (auto* a : {&sx_, &sy_, &sz_, &svx_, &svy_, &svz_, &rho_, &p_, &ax_, &ay_, &az_}) a->reserve(n);
    sid_.reserve(n);
    skey_.reserve(n);
    chunk_a2_.reserve(chunks_);
    chunk_v2_.reserve(chunks_);
    chunk_error_.reserve(chunks_);
    for (std::size_t c = 0; c < chunks_; ++c) chunk_a2_[c] = 0, chunk_v2_[c] = 0, chunk_error_[c] = 0;
    if (desc.solver == SphSolver::kDfsph) {
        for (auto* a : {&pair_begin_, &pair_end_}) a->reserve(n);
        for (auto* a : {&ratio_, &factor_, &k_, &wall_gx_, &wall_gy_, &wall_gz_, &support_, &k_div_sum_,
                        &k_den_sum_, &k_div_last_, &k_den_last_, &k_den_before_, &k_den_before_next_})
            a->reserve(n);
        source_.reserve(n);
        v4_.reserve(4 * n);
        v4_next_.reserve(4 * n);
        x4_.reserve(4 * n);
        lists_.resize(chunks_);
        const std::size_t per_chunk = n / chunks_ + 1;
        for (DfsphChunkLists& l : lists_) l.pairs.reserve(per_chunk * kListPairs);
    }
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
    if (desc_.solver == SphSolver::kDfsph)  // the first two substeps' warm starts read them (zero anyway)
        for (std::size_t i = 0; i < n_; ++i) k_div_last_[i] = 0, k_den_last_[i] = 0, k_den_before_[i] = 0;
    last_phase_ = kPhaseCount;
    divergence_iterations_ = density_iterations_ = 0;
    density_error_ = 0;
    dt_last_ = 0;
    look_in_prediction_ = true;
}

void SphSimulation::begin_frame(ParticleSet& ps, std::uint64_t frame) {
    if (ps.size() != n_) throw std::logic_error("SphSimulation: particle count changed since seed()");
    const double frame_dt = desc_.dt;
    offset_begin_ = offset_now_;
    offset_end_ = scripted_offset(double(frame + 1) * frame_dt);

    float v2 = 0;
    const auto vx = ps.vx(), vy = ps.vy(), vz = ps.vz();
    for (std::size_t i = 0; i < n_; ++i) v2 = std::max(v2, vx[i] * vx[i] + vy[i] * vy[i] + vz[i] * vz[i]);
    const Vec3f wall_v = (offset_end_ - offset_begin_) * static_cast<float>(1.0 / frame_dt);
    wall_speed_ = length(wall_v);
    if (const double most = sph_max_tank_speed(desc_); !(double(wall_speed_) <= most))
        throw std::invalid_argument(
            "the tank moves at " + io::number_text(wall_speed_) + " m/s in frame " + std::to_string(frame) +
            ", more than max_substeps substeps a frame can follow (" + io::number_text(most) +
            " m/s): slow the container_motion or the input track, or raise "
            "sph.max_substeps");
    v2_start_ = v2;
    substep_ = 0;
    frame_left_ = frame_dt;
    last_phase_ = kPhaseCount;
    divergence_iterations_ = density_iterations_ = 0;
    density_error_ = 0;
    if (desc_.solver == SphSolver::kDfsph) {  // each substep picks its own length (start_dfsph_substep)
        substeps_ = 0;
        return;
    }
    // WCSPH: equal substeps from the limits at the frame's start: CFL on c0 + |v|max, the acceleration of
    // the last substep, viscosity.
    const double vmax = std::sqrt(double(v2)) + double(wall_speed_);
    const double h = fluid_.kernels.h;
    float a2 = dot(desc_.gravity, desc_.gravity);
    for (std::size_t c = 0; c < chunks_; ++c) a2 = std::max(a2, chunk_a2_[c]);
    double limit = double(desc_.step_cfl()) * h / (double(desc_.sound_speed) + vmax);
    if (a2 > 0) limit = std::min(limit, 0.25 * std::sqrt(h / std::sqrt(double(a2))));
    if (desc_.viscosity > 0) limit = std::min(limit, 0.125 * h * h * desc_.rest_density / desc_.viscosity);
    const double wanted = std::ceil(frame_dt / limit - 1e-9);
    substeps_ = static_cast<int>(std::clamp(wanted, 1.0, double(desc_.max_substeps)));
    dt_sub_ = static_cast<float>(frame_dt / substeps_);
}

// DFSPH: a substep is limited by the speed at its start (the fastest particle: v2_start_ on a frame's
// first substep, the last integration's otherwise; plus the walls' speed) and the speed a substep of
// gravity adds, dt <= cfl d / (v + g dt), solved for dt; by keeping the displacement gravity alone gives
// (g dt^2) under 5 % of the spacing (the pressure solve predicts density to first order in the step); and
// by the viscous limit. The frame's remaining time is split into equal substeps of at most that length,
// so the frame ends on time without a sliver of a last step, and the frame takes at most max_substeps.
void SphSimulation::start_dfsph_substep() {
    float v2 = v2_start_;
    if (substep_ > 0) {
        v2 = 0;
        for (std::size_t c = 0; c < chunks_; ++c) v2 = std::max(v2, chunk_v2_[c]);
    }
    const double v = std::sqrt(double(v2)) + double(wall_speed_);
    const double g = double(length(desc_.gravity)), d = desc_.spacing, h = fluid_.kernels.h;
    const double reach = double(desc_.step_cfl()) * d;
    const double root = v + std::sqrt(v * v + 4.0 * g * reach);
    double limit = root > 0 ? 2.0 * reach / root : frame_left_;
    if (g > 0) limit = std::min(limit, std::sqrt(0.05 * d / g));
    if (desc_.viscosity > 0) limit = std::min(limit, 0.125 * h * h * desc_.rest_density / desc_.viscosity);
    const double most = double(desc_.max_substeps - substep_);  // >= 1: the frame ends at max_substeps
    const double count = std::clamp(std::ceil(frame_left_ / limit - 1e-9), 1.0, most);
    const double dt = frame_left_ / count;
    frame_left_ = count > 1.0 ? frame_left_ - dt : 0.0;
    dt_sub_ = static_cast<float>(dt);
}

bool SphSimulation::solve_done(float max_error_percent) {
    double sum = 0;
    for (std::size_t c = 0; c < chunks_; ++c) sum += chunk_error_[c];
    const double average = n_ > 0 ? sum / double(n_) : 0.0;
    const bool done = average <= 0.01 * double(max_error_percent) || iterations_ >= desc_.max_iterations;
    if (done && solve_ == Solve::kDensity) density_error_ = std::max(density_error_, average);
    return done;
}

std::size_t SphSimulation::next_phase() {
    const bool dfsph = desc_.solver == SphSolver::kDfsph;
    std::size_t next = kPhaseCount;
    switch (last_phase_) {
        case kIntegrate:
            if (dfsph) {  // this substep's sums are the next one's warm start
                std::swap(k_div_sum_, k_div_last_);
                std::swap(k_den_sum_, k_den_last_);
                std::swap(k_den_before_, k_den_before_next_);
                dt_last_ = dt_sub_;
            }
            [[fallthrough]];
        case kPhaseCount:
            next = (dfsph ? frame_left_ > 0.0 : substep_ < substeps_) ? kSubstep : kPhaseCount;
            break;
        case kGridScatter:
            next = dfsph ? kWarmStart : kDensity;
            break;
        case kNeighbours:  // the divergence solve's warm start is applied: its first residual comes next
            solve_ = Solve::kDivergence, iterations_ = 0, chebyshev_ = 1.0f;
            divergence_done_ = false;
            next = look_in_prediction_ ? kPredict : kDivergence;
            break;
        case kDivergence:
            divergence_done_ = solve_done(desc_.max_divergence_error);
            next = divergence_done_ ? kPredict : kCorrect;
            break;
        case kPredict:
            if (!divergence_done_ &&
                !solve_done(desc_.max_divergence_error)) {  // the prediction is thrown away
                next = kCorrect;
                break;
            }
            look_in_prediction_ = iterations_ == 0;
            // The density solve's warm start is applied with the prediction: its first residual comes next.
            std::swap(v4_, v4_next_);
            solve_ = Solve::kDensity, iterations_ = 0, chebyshev_ = 1.0f;
            next = kDensityError;
            break;
        case kCorrect:
            ++iterations_;
            chebyshev_ = dfsph_chebyshev_weight(desc_.chebyshev, iterations_, chebyshev_);
            ++(solve_ == Solve::kDivergence ? divergence_iterations_ : density_iterations_);
            next = solve_ == Solve::kDivergence ? kDivergence : kDensityError;
            break;
        case kDensityError:
            next = solve_done(desc_.max_density_error) ? kIntegrate : kCorrect;
            break;
        default:  // the fixed sequences: substep, the grid phases, WCSPH's density and forces
            next = last_phase_ + 1;
            break;
    }
    last_phase_ = next;
    return next;
}

DfsphContext SphSimulation::dfsph_context() const {
    DfsphContext c{sx_.span(n_),
                   sy_.span(n_),
                   sz_.span(n_),
                   x4_.span(4 * n_),
                   lists_,
                   pair_begin_.span(n_),
                   pair_end_.span(n_),
                   wall_gx_.span(n_),
                   wall_gy_.span(n_),
                   wall_gz_.span(n_),
                   support_.span(n_),
                   {walls_.velocity[0], walls_.velocity[1], walls_.velocity[2]},
                   0.75f * full_neighbours_};
    return c;
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
            // The container moves linearly over the frame; f: the fraction of the frame at this substep's
            // end.
            float f = 0.0f;
            if (desc_.solver == SphSolver::kDfsph) {
                start_dfsph_substep();
                substeps_ = substep_ + 1;
                f = frame_left_ > 0.0 ? static_cast<float>(1.0 - frame_left_ / double(desc_.dt)) : 1.0f;
            } else {
                f = static_cast<float>(substep_ + 1) / static_cast<float>(substeps_);
            }
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
            key_ranges_[chunk] =
                sph_grid_count_chunk(grid_, x.subspan(b, e - b), y.subspan(b, e - b), z.subspan(b, e - b),
                                     keys_.span(n_).subspan(b, e - b),
                                     counts_.span(chunks_ * cells).subspan(chunk * cells, cells));
            break;
        }
        case kGridCursors: {
            const auto first = static_cast<std::uint32_t>(std::size_t(chunk) * cells / chunks_);
            const auto last = static_cast<std::uint32_t>(std::size_t(chunk + 1) * cells / chunks_);
            sph_grid_cursors(cells, key_ranges_, first, last, counts_.span(chunks_ * cells),
                             cursors_.span(chunks_ * cells), cell_total_.span(cells));
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
            const bool dfsph = desc_.solver == SphSolver::kDfsph;
            const SphSortedOut out{
                sx_.span(n_),  sy_.span(n_),   sz_.span(n_),
                svx_.span(n_), svy_.span(n_),  svz_.span(n_),
                sid_.span(n_), skey_.span(n_), dfsph ? source_.span(n_) : std::span<std::uint32_t>{}};
            sph_grid_scatter_chunk(in, keys_.span(n_).subspan(b, e - b), cell_start_.span(cells + 1),
                                   cursors_.span(chunks_ * cells).subspan(chunk * cells, cells), out, b);
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
            if (desc_.solver == SphSolver::kDfsph) {  // v* (ax_, ay_, az_) is the new velocity
                const SphParticlesIn in{sx_.span(n_), sy_.span(n_), sz_.span(n_), ax_.span(n_),
                                        ay_.span(n_), az_.span(n_), sid_.span(n_)};
                chunk_v2_[chunk] = sph_integrate(in, {}, b, e, dt_sub_, boundary_, ps.spans());
                break;
            }
            const SphParticlesIn in{sx_.span(n_),  sy_.span(n_),  sz_.span(n_), svx_.span(n_),
                                    svy_.span(n_), svz_.span(n_), sid_.span(n_)};
            chunk_v2_[chunk] = sph_integrate(in, {ax_.span(n_), ay_.span(n_), az_.span(n_)}, b, e, dt_sub_,
                                             boundary_, ps.spans());
            break;
        }
        case kWarmStart: {
            // Each solve's starting sum from the last substeps' stiffness (kWarmStartShare,
            // kDensityWarmShare), scaled to this step: the list build applies the divergence solve's, the
            // prediction the density solve's.
            const float ratio = dt_last_ > 0.0f ? dt_sub_ / dt_last_ : 0.0f;
            const float warm_div = kWarmStartShare * ratio, warm_den = kDensityWarmShare * ratio;
            for (std::size_t i = b; i < e; ++i) {
                const std::uint32_t s = source_[i];
                k_div_sum_[i] = dfsph_warm_stiffness(warm_div, k_div_last_[s]);
                k_den_sum_[i] = dfsph_warm_stiffness(warm_den, std::min(k_den_last_[s], k_den_before_[s]));
                k_den_before_next_[i] = k_den_last_[s];
            }
            break;
        }
        case kNeighbours: {
            DfsphParticleOut out{pair_begin_.span(n_), pair_end_.span(n_), ratio_.span(n_),
                                 factor_.span(n_),     wall_gx_.span(n_),  wall_gy_.span(n_),
                                 wall_gz_.span(n_),    support_.span(n_),  x4_.span(4 * n_)};
            out.k_warm = k_div_sum_.span(n_);
            out.vx = svx_.span(n_), out.vy = svy_.span(n_), out.vz = svz_.span(n_), out.v4 = v4_.span(4 * n_);
            dfsph_build_lists(neighbourhood(), cubic_, volume_, walls_, wall_table_, full_neighbours_, b, e,
                              lists_[chunk], out);
            for (std::size_t i = b; i < e; ++i) rho_[i] = desc_.rest_density * ratio_[i];
            break;
        }
        case kCorrect: {
            float* sum = solve_ == Solve::kDivergence ? k_div_sum_.data() : k_den_sum_.data();
            for (std::size_t i = b; i < e; ++i) sum[i] += k_[i];
            if (solve_ == Solve::kDivergence) {
                dfsph_correct(dfsph_context(), chunk, b, e, k_.span(n_),
                              {svx_.span(n_), svy_.span(n_), svz_.span(n_), v4_.span(4 * n_)});
            } else {
                dfsph_correct(dfsph_context(), chunk, b, e, k_.span(n_),
                              {ax_.span(n_), ay_.span(n_), az_.span(n_), v4_.span(4 * n_)});
            }
            break;
        }
        case kDivergence:
            chunk_error_[chunk] =
                dfsph_divergence_residual(dfsph_context(), chunk, b, e, dt_sub_, v4_.span(4 * n_),
                                          {factor_.span(n_), k_div_sum_.span(n_), k_.span(n_)}, chebyshev_);
            break;
        case kPredict: {
            const float g[3] = {fluid_.gx, fluid_.gy, fluid_.gz};
            const DfsphPredictSums sums = dfsph_predict(
                dfsph_context(), chunk, b, e, dt_sub_, desc_.viscosity / desc_.rest_density, cubic_.h, g,
                v4_.span(4 * n_), k_den_sum_.span(n_), {factor_.span(n_), k_div_sum_.span(n_), k_.span(n_)},
                {ax_.span(n_), ay_.span(n_), az_.span(n_), v4_next_.span(4 * n_)});
            chunk_v2_[chunk] = sums.max_v2;
            chunk_error_[chunk] = sums.divergence_error;
            break;
        }
        case kDensityError:
            chunk_error_[chunk] = dfsph_residual(
                dfsph_context(), chunk, b, e, dt_sub_, v4_.span(4 * n_), ratio_.span(n_), factor_.span(n_),
                k_den_sum_.span(n_), k_.span(n_), std::min(1.0f, dt_sub_ / kDensityCatchUp), chebyshev_);
            break;
        default:
            throw std::out_of_range("SphSimulation::run_phase: no such phase");
    }
}

void SphSimulation::end_frame(ParticleSet&) {
    time_ += desc_.dt;
}

void SphSimulation::run_phases_serial(ParticleSet& ps) {
    for (std::size_t p = next_phase(); p != kPhaseCount; p = next_phase()) {
        const std::size_t n = kPhases[p].parallel ? chunks_ : 1;
        for (std::size_t c = 0; c < n; ++c) run_phase(p, c, ps);
    }
}

void SphSimulation::step_serial(ParticleSet& ps, std::uint64_t frame) {
    begin_frame(ps, frame);
    run_phases_serial(ps);
    end_frame(ps);
}

void SphSimulation::step_parallel(ParticleSet& ps, std::uint64_t frame) {
    begin_frame(ps, frame);
    for (std::size_t p = next_phase(); p != kPhaseCount; p = next_phase()) {
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
    end_frame(ps);
}

}  // namespace rivulet
