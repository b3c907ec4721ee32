#include "systems/slices/slices_settings_json.h"

#include "systems/io/json_fields.h"

namespace rivulet {

template <class F>
void members(SlicesSettings& s, F&& f) {
    f("radius", s.radius), f("voxel", s.voxel), f("block_cubes", s.block_cubes), f("rc_factor", s.rc_factor);
    f("iso", s.iso), f("max_blocks", s.max_blocks), f("max_triangles", s.max_triangles);
    f("max_grid_cubes", s.max_grid_cubes), f("exhaustive_seeds", s.exhaustive_seeds);
}

nlohmann::json slices_settings_to_json(const SlicesSettings& settings) {
    return json_fields::write(settings);
}

SlicesSettings slices_settings_from_json(const nlohmann::json& doc, const std::string& origin) {
    SlicesSettings s;
    json_fields::read(doc, s, origin);
    if (const std::string problem = s.validate(); !problem.empty()) json_fields::fail(origin, problem);
    return s;
}

}  // namespace rivulet
