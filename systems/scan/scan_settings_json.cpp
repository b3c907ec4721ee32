#include "systems/scan/scan_settings_json.h"

#include "systems/io/json_fields.h"

namespace rivulet {

template <class F>
void members(CrossSectionParams& c, F&& f) {
    f("function", c.function), f("smoothing_iterations", c.smoothing_iterations), f("tension", c.tension);
}
template <class F>
void members(ScanSettings& s, F&& f) {
    f("u", s.u), f("v", s.v), f("max_groups", s.max_groups), f("radius", s.radius), f("epsilon", s.epsilon);
    f("epsilon_diameters", s.epsilon_diameters), f("section", s.section), f("v_top", s.v_top);
    f("v_bottom", s.v_bottom), f("axis", s.axis);
}

// The radial function by the names the CLI uses (--radial).
void read(const nlohmann::json& j, RadialFunction& out, const std::string& where) {
    if (j == "maxima") {
        out = RadialFunction::kCircleMaxima;
    } else if (j == "gaussian") {
        out = RadialFunction::kGaussianBlend;
    } else {
        json_fields::fail(where, "expected \"maxima\" or \"gaussian\"");
    }
}
nlohmann::json write(RadialFunction f) {
    return f == RadialFunction::kCircleMaxima ? "maxima" : "gaussian";
}

// Cylinder axes by the names the CLI uses (--axis).
void read(const nlohmann::json& j, CylinderAxis& out, const std::string& where) {
    if (j == "vertical") {
        out = CylinderAxis::kVertical;
    } else if (j == "path") {
        out = CylinderAxis::kPath;
    } else {
        json_fields::fail(where, "expected \"vertical\" or \"path\"");
    }
}
nlohmann::json write(CylinderAxis a) {
    return a == CylinderAxis::kVertical ? "vertical" : "path";
}

nlohmann::json scan_settings_to_json(const ScanSettings& settings) {
    return json_fields::write(settings);
}

ScanSettings scan_settings_from_json(const nlohmann::json& doc, const std::string& origin) {
    ScanSettings s;
    json_fields::read(doc, s, origin);
    if (const std::string problem = s.validate(); !problem.empty()) json_fields::fail(origin, problem);
    return s;
}

}  // namespace rivulet
