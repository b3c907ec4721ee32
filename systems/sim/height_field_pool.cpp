#include "systems/sim/height_field_pool.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "systems/scenes/scene_limits.h"

namespace rivulet {

namespace {

// Fraction of the explicit scheme's stability limit used, so rounding never tips it over.
constexpr double kCourantSafety = 0.5;
constexpr int kMaxSubsteps = 4096;

void require(bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("pool: " + what);
}

}  // namespace

HeightFieldPool::HeightFieldPool(const PoolDesc& desc, float frame_dt) : desc_(desc) {
    require(desc.nx >= 2 && desc.nx <= kMaxPoolSamples && desc.nz >= 2 && desc.nz <= kMaxPoolSamples,
            "nx, nz must be in [2, " + std::to_string(kMaxPoolSamples) + "]");
    require(std::isfinite(desc.x0) && std::isfinite(desc.z0) && std::isfinite(desc.level),
            "non-finite placement");
    require(std::isfinite(desc.size_x) && std::isfinite(desc.size_z) && desc.size_x > 0 && desc.size_z > 0,
            "size must be positive");
    require(std::isfinite(desc.wave_speed) && desc.wave_speed >= 0, "wave_speed must be >= 0");
    require(std::isfinite(desc.damping) && desc.damping >= 0, "damping must be >= 0");
    require(std::isfinite(desc.drain) && desc.drain >= 0, "drain must be >= 0");
    require(std::isfinite(desc.impulse_scale) && desc.impulse_scale >= 0, "impulse_scale must be >= 0");
    require(std::isfinite(desc.max_dip) && desc.max_dip >= 0, "max_dip must be >= 0");
    require(std::isfinite(frame_dt) && frame_dt > 0, "frame dt must be positive");

    dx_ = desc.size_x / static_cast<float>(desc.nx - 1);
    dz_ = desc.size_z / static_cast<float>(desc.nz - 1);
    const double c = desc.wave_speed;
    const double courant = c * frame_dt * std::sqrt(1.0 / (double(dx_) * dx_) + 1.0 / (double(dz_) * dz_));
    const double needed = std::ceil(courant / kCourantSafety);
    require(needed <= kMaxSubsteps, "wave_speed too high for the grid spacing");
    substeps_ = std::max(1, static_cast<int>(needed));

    const double h = double(frame_dt) / substeps_;
    h_ = static_cast<float>(h);
    kx_ = static_cast<float>(c * c * h / (double(dx_) * dx_));
    kz_ = static_cast<float>(c * c * h / (double(dz_) * dz_));
    damp_ = static_cast<float>(std::exp(-double(desc.damping) * h));
    drain_ = static_cast<float>(std::exp(-double(desc.drain) * h));

    count_ = static_cast<std::size_t>(desc.nx) * static_cast<std::size_t>(desc.nz);
    dev_.reserve(count_), vel_.reserve(count_), absolute_.reserve(count_);
    std::fill_n(dev_.data(), count_, 0.0f);
    std::fill_n(vel_.data(), count_, 0.0f);
    publish();
}

void HeightFieldPool::apply_impulse(float x, float z, float momentum) {
    const float fx = (x - desc_.x0) / dx_;
    const float fz = (z - desc_.z0) / dz_;
    const float last_x = static_cast<float>(desc_.nx - 1), last_z = static_cast<float>(desc_.nz - 1);
    if (!(fx >= 0 && fz >= 0 && fx <= last_x && fz <= last_z)) return;
    const float depth = std::min(desc_.impulse_scale * std::max(momentum, 0.0f), desc_.max_dip);
    if (!(depth > 0)) return;

    const int ix = std::min(static_cast<int>(fx), desc_.nx - 2);
    const int iz = std::min(static_cast<int>(fz), desc_.nz - 2);
    const float tx = fx - static_cast<float>(ix), tz = fz - static_cast<float>(iz);
    const float weights[4] = {(1 - tx) * (1 - tz), tx * (1 - tz), (1 - tx) * tz, tx * tz};
    const std::size_t base = static_cast<std::size_t>(iz) * desc_.nx + ix;
    const std::size_t cells[4] = {base, base + 1, base + desc_.nx, base + desc_.nx + 1};
    for (int k = 0; k < 4; ++k) {
        float& d = dev_[cells[k]];
        // A sample already deeper than max_dip stays where it is rather than being lifted to the clamp.
        d = std::max(d - weights[k] * depth, std::min(d, -desc_.max_dip));
        absolute_[cells[k]] = desc_.level + d;
    }
}

void HeightFieldPool::step() {
    const int nx = desc_.nx, nz = desc_.nz;
    float* dev = dev_.data();
    float* vel = vel_.data();
    for (int s = 0; s < substeps_; ++s) {
        for (int iz = 0; iz < nz; ++iz) {
            // Clamped neighbours mirror the edge sample: zero slope there, so waves reflect.
            const float* row = dev + static_cast<std::size_t>(iz) * nx;
            const float* up = dev + static_cast<std::size_t>(std::max(iz - 1, 0)) * nx;
            const float* down = dev + static_cast<std::size_t>(std::min(iz + 1, nz - 1)) * nx;
            float* v = vel + static_cast<std::size_t>(iz) * nx;
            for (int ix = 0; ix < nx; ++ix) {
                const float left = row[std::max(ix - 1, 0)];
                const float right = row[std::min(ix + 1, nx - 1)];
                const float lap_x = (left - row[ix]) + (right - row[ix]);
                const float lap_z = (up[ix] - row[ix]) + (down[ix] - row[ix]);
                v[ix] = (v[ix] + kx_ * lap_x + kz_ * lap_z) * damp_;
            }
        }
        for (std::size_t i = 0; i < count_; ++i) dev[i] = (dev[i] + h_ * vel[i]) * drain_;
    }
    publish();
}

void HeightFieldPool::publish() {
    for (std::size_t i = 0; i < count_; ++i) absolute_[i] = desc_.level + dev_[i];
}

HeightFieldView HeightFieldPool::view() const {
    return {desc_.nx, desc_.nz, desc_.x0, desc_.z0, dx_, dz_, absolute_.span(count_)};
}

double HeightFieldPool::deviation_energy() const {
    double sum = 0;
    for (std::size_t i = 0; i < count_; ++i) sum += double(dev_[i]) * dev_[i];
    return sum;
}

}  // namespace rivulet
