#include "systems/volume/volume_settings_json.h"

#include "systems/io/json_fields.h"

namespace rivulet {

template <class F>
void members(VolumeSettings& s, F&& f) {
    f("radius", s.radius), f("kernel_radii", s.kernel_radii), f("voxel", s.voxel), f("max_dim", s.max_dim);
    f("iso", s.iso), f("max_bricks", s.max_bricks);
}

nlohmann::json volume_settings_to_json(const VolumeSettings& settings) {
    return json_fields::write(settings);
}

VolumeSettings volume_settings_from_json(const nlohmann::json& doc, const std::string& origin) {
    VolumeSettings s;
    json_fields::read(doc, s, origin);
    if (const std::string problem = s.validate(); !problem.empty()) json_fields::fail(origin, problem);
    return s;
}

}  // namespace rivulet
