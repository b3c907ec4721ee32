#include "systems/render/screen_fluid_json.h"

#include "systems/io/json_fields.h"

namespace rivulet {

template <class F>
void members(ScreenFluidSettings& s, F&& f) {
    f("filter_iterations", s.filter_iterations), f("filter_radius", s.filter_radius);
    f("depth_sigma", s.depth_sigma), f("max_filter_pixels", s.max_filter_pixels);
    f("max_filter_taps", s.max_filter_taps), f("fill_holes", s.fill_holes);
    f("thickness_downsample", s.thickness_downsample);
    f("thickness_blur", s.thickness_blur);
    f("spray_neighbours", s.spray_neighbours), f("spray_distance", s.spray_distance);
}

// The smoothing is a name, kept beside the numeric members.
nlohmann::json screen_fluid_settings_to_json(const ScreenFluidSettings& settings) {
    nlohmann::json doc = json_fields::write(settings);
    doc["smoothing"] = depth_smoothing_name(settings.smoothing);
    return doc;
}

ScreenFluidSettings screen_fluid_settings_from_json(const nlohmann::json& doc, const std::string& origin) {
    ScreenFluidSettings s;
    nlohmann::json numbers = doc;
    if (numbers.is_object() && numbers.contains("smoothing")) {
        std::string name;
        json_fields::read(numbers["smoothing"], name, origin + ".smoothing");
        if (!parse_depth_smoothing(name, s.smoothing))
            json_fields::fail(origin + ".smoothing",
                              "'" + name + "' is not bilateral, curvature-flow or narrow-range");
        numbers.erase("smoothing");
    }
    json_fields::read(numbers, s, origin);
    if (const std::string problem = s.validate(); !problem.empty()) json_fields::fail(origin, problem);
    return s;
}

}  // namespace rivulet
