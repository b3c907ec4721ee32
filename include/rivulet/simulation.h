#pragma once
// Rivulet's scenes as a particle source: a built-in scene (`rivulet list` names them) or a scene JSON file
// (docs/scenes.md), simulated frame by frame by the same jobs as `rivulet simulate`, deterministic at any
// thread count.
//
//   rivulet::Simulation sim("dambreak");          // warm-up frames already simulated
//   for (int f = 0; f < 100; ++f) {
//       sim.step();
//       auto p = sim.positions();                  // the frame's particles, one array per coordinate
//   }
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace rivulet {

// The frame's particles, one array per coordinate; valid until the next step().
struct PositionsView {
    std::span<const float> x, y, z;
    std::size_t size() const { return x.size(); }
};

class Simulation {
  public:
    // `scene`: a built-in scene's name or a scene file's path. `warmup`: frames simulated before the
    // first step() (-1: the scene's own warm-up). `threads` as SurfaceSettings::threads.
    explicit Simulation(const std::string& scene, int warmup = -1, int threads = 0);
    ~Simulation();
    Simulation(Simulation&&) noexcept;
    Simulation& operator=(Simulation&&) noexcept;

    // Simulates one frame of 1 / frame_rate() seconds.
    void step();
    PositionsView positions() const;
    // Frames step() has simulated (warm-up not counted).
    std::uint64_t frame() const;

    const std::string& name() const;
    float particle_radius() const;  // the scene's, as `rivulet run` meshes it
    float frame_rate() const;
    std::size_t max_particles() const;

    static std::vector<std::string> builtin_scenes();

  private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace rivulet
