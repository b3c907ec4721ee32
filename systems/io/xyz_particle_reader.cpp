#include "systems/io/line_fields.h"
#include "systems/io/particle_readers.h"
#include "systems/io/text_parse.h"

namespace rivulet::io {

// One particle per line: the first three fields are x y z, further columns (ids, velocities, ...) are
// ignored; '#' lines are comments.
ParticleCloud read_xyz_particles(const std::string& path) {
    InputFile in(path);
    in.require_text_size("XYZ");
    LineFields lines(in);
    ParticleCloud cloud;
    while (lines.next()) {
        const auto f = lines.fields();
        if (f[0].front() == '#') continue;
        if (f.size() < 3) {
            lines.fail("expected at least 3 numbers (x y z), got " + std::to_string(f.size()) + " field" +
                       (f.size() == 1 ? "" : "s"));
        }
        double v[3];
        for (int a = 0; a < 3; ++a) {
            const auto value = parse_double(f[a]);
            if (!value) lines.fail(quoted(f[a]) + " is not a number");
            v[a] = *value;
        }
        cloud.x.push_back(narrow_coordinate(v[0]));
        cloud.y.push_back(narrow_coordinate(v[1]));
        cloud.z.push_back(narrow_coordinate(v[2]));
    }
    return cloud;
}

}  // namespace rivulet::io
