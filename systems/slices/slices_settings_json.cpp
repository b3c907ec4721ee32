#include "systems/slices/slices_settings_json.h"

#include "systems/io/json_fields.h"

namespace rivulet {

template <class F>
void members(SlicesSettings& s, F&& f) {
    f("radius", s.radius), f("voxel", s.voxel), f("block_cubes", s.block_cubes), f("spacing", s.spacing);
    f("rc_factor", s.rc_factor);
    f("iso", s.iso), f("max_blocks", s.max_blocks), f("max_triangles", s.max_triangles);
    f("max_grid_cubes", s.max_grid_cubes), f("exhaustive_seeds", s.exhaustive_seeds);
    f("anisotropy", s.anisotropy), f("anisotropy_smoothing", s.anisotropy_smoothing);
}

nlohmann::json slices_settings_to_json(const SlicesSettings& settings) {
    nlohmann::json doc = json_fields::write(settings);
    doc["field"] = slice_field_name(settings.field);
    return doc;
}

SlicesSettings slices_settings_from_json(const nlohmann::json& doc, const std::string& origin) {
    SlicesSettings s;
    // Settings written before the spacing field existed name no field and meant the classic one, so old
    // recordings replay to the same bytes.
    s.field = SliceField::kClassic;
    nlohmann::json rest = doc;
    if (doc.is_object() && doc.contains("field")) {
        const nlohmann::json& name = doc.at("field");
        if (!name.is_string() || !parse_slice_field(name.get<std::string>(), s.field))
            json_fields::fail(origin + ".field", "expected \"spacing\" or \"classic\"");
        rest.erase("field");
    }
    json_fields::read(rest, s, origin);
    if (const std::string problem = s.validate(); !problem.empty()) json_fields::fail(origin, problem);
    return s;
}

}  // namespace rivulet
