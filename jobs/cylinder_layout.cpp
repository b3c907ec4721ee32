#include "jobs/cylinder_layout.h"

#include <cassert>

namespace rivulet {

void write_cylinder_indices(const CylinderLayout& layout, std::span<std::uint32_t> out) {
    assert(out.size() == layout.index_count());
    const std::uint32_t u = layout.u;
    std::size_t n = 0;
    // Ring r lies above ring r+1; side vertex k sits at angle 2*pi*k/U, offset (cos, 0, sin) from the
    // ring centre. With that orientation these orders wind counter-clockwise seen from outside.
    for (std::uint32_t b = 0; b + 1 < layout.v; ++b) {
        for (std::uint32_t k = 0; k < u; ++k) {
            const std::uint32_t k1 = (k + 1) % u;
            const std::uint32_t a = layout.side_vertex(b, k), a1 = layout.side_vertex(b, k1);
            const std::uint32_t c = layout.side_vertex(b + 1, k), c1 = layout.side_vertex(b + 1, k1);
            out[n++] = a, out[n++] = c1, out[n++] = c;
            out[n++] = a, out[n++] = a1, out[n++] = c1;
        }
    }
    for (std::uint32_t r = 0; r < layout.v; ++r) {
        for (std::uint32_t k = 0; k < u; ++k) {
            out[n++] = layout.top_pole(r), out[n++] = layout.side_vertex(r, (k + 1) % u),
            out[n++] = layout.side_vertex(r, k);
        }
    }
    for (std::uint32_t r = 0; r < layout.v; ++r) {
        for (std::uint32_t k = 0; k < u; ++k) {
            out[n++] = layout.bottom_pole(r), out[n++] = layout.side_vertex(r, k),
            out[n++] = layout.side_vertex(r, (k + 1) % u);
        }
    }
    assert(n == out.size());
}

}  // namespace rivulet
