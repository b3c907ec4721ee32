#pragma once
// The resting pool (Hoetzlein & Höllerer 2009 §3): a 2D wave equation on a height field with reflective
// edges. Falling particles push the surface down where they land; waves carry the dip outward and damping
// calms it. Explicit symplectic Euler with as many internal substeps per frame as the CFL condition asks for.
#include <cstddef>

#include "systems/particles/aligned_array.h"
#include "systems/render/frame_view.h"
#include "systems/scenes/scene.h"

namespace rivulet {

class HeightFieldPool {
  public:
    // Allocates everything; throws std::invalid_argument for an unusable description.
    HeightFieldPool(const PoolDesc& desc, float frame_dt);

    // Pushes the surface down by impulse_scale * momentum (at most max_dip), spread bilinearly over the
    // four samples around (x, z). Points outside the rectangle are ignored.
    void apply_impulse(float x, float z, float momentum);
    // Advances one frame.
    void step();

    // Absolute heights (y), as of the last step or impulse.
    HeightFieldView view() const;
    int substeps() const { return substeps_; }
    // Sum of squared deviations from the calm level.
    double deviation_energy() const;

  private:
    void publish();

    PoolDesc desc_;
    float dx_, dz_;
    int substeps_ = 1;
    float h_ = 0;            // substep length
    float kx_ = 0, kz_ = 0;  // c^2 h / dx^2, c^2 h / dz^2
    float damp_ = 1;         // velocity kept per substep
    float drain_ = 1;        // deviation kept per substep
    std::size_t count_ = 0;
    AlignedArray<float> dev_;       // deviation from level
    AlignedArray<float> vel_;       // d(dev)/dt
    AlignedArray<float> absolute_;  // level + dev, what views show
};

}  // namespace rivulet
