#include "systems/render/screen_fluid_json.h"

#include "systems/io/json_fields.h"

namespace rivulet {

template <class F>
void members(ScreenFluidSettings& s, F&& f) {
    f("filter_iterations", s.filter_iterations), f("filter_radius", s.filter_radius);
    f("depth_sigma", s.depth_sigma), f("max_filter_pixels", s.max_filter_pixels);
    f("thickness_downsample", s.thickness_downsample);
}

nlohmann::json screen_fluid_settings_to_json(const ScreenFluidSettings& settings) {
    return json_fields::write(settings);
}

ScreenFluidSettings screen_fluid_settings_from_json(const nlohmann::json& doc, const std::string& origin) {
    ScreenFluidSettings s;
    json_fields::read(doc, s, origin);
    if (const std::string problem = s.validate(); !problem.empty()) json_fields::fail(origin, problem);
    return s;
}

}  // namespace rivulet
