#include <cmath>
#include <memory>
#include <vector>

#include "systems/io/coordinate.h"
#include "systems/io/line_fields.h"
#include "systems/io/mesh_formats.h"
#include "systems/io/ply_header.h"
#include "systems/io/text_parse.h"

namespace rivulet::io {
namespace {

// The body as a stream of values in declaration order, so one walk over the elements serves every
// encoding. Lists (faces) make entry sizes variable, so unlike the particle reader this goes value by
// value.
class ValueSource {
  public:
    virtual ~ValueSource() = default;
    virtual void begin_entry(const PlyElement& e, std::uint64_t index) = 0;
    virtual double next(PlyScalar type) = 0;
    virtual void end_entry() = 0;
};

class BinarySource final : public ValueSource {
  public:
    BinarySource(InputFile& in, bool big_endian) : in_(in), big_endian_(big_endian) {
        data_.resize(in.remaining());
        data_.resize(in.read(data_.data(), data_.size()));
    }
    void begin_entry(const PlyElement& e, std::uint64_t index) override {
        element_ = &e;
        index_ = index;
    }
    double next(PlyScalar type) override {
        const std::size_t n = ply_scalar_size(type);
        if (data_.size() - pos_ < n) {
            in_.fail("truncated binary data in element '" + element_->name + "' at entry " +
                     std::to_string(index_) + " of " + std::to_string(element_->count));
        }
        const double v = ply_decoder(type, big_endian_)(data_.data() + pos_);
        pos_ += n;
        return v;
    }
    void end_entry() override {}

  private:
    InputFile& in_;
    bool big_endian_;
    std::vector<std::byte> data_;
    std::size_t pos_ = 0;
    const PlyElement* element_ = nullptr;
    std::uint64_t index_ = 0;
};

// One entry per line, as every PLY writer emits it.
class AsciiSource final : public ValueSource {
  public:
    explicit AsciiSource(InputFile& in) : in_(in), lines_(in) {}
    void begin_entry(const PlyElement& e, std::uint64_t index) override {
        element_ = &e;
        if (!lines_.next()) {
            in_.fail("truncated ascii data: element '" + e.name + "' ends after " + std::to_string(index) +
                     " of " + std::to_string(e.count) + " entries");
        }
        next_ = 0;
    }
    double next(PlyScalar) override {
        const auto f = lines_.fields();
        if (next_ >= f.size()) lines_.fail("too few values for an entry of element '" + element_->name + "'");
        const auto v = parse_double(f[next_]);
        if (!v) lines_.fail(quoted(f[next_]) + " is not a number");
        ++next_;
        return *v;
    }
    void end_entry() override {
        if (next_ != lines_.fields().size())
            lines_.fail("too many values for an entry of element '" + element_->name + "'");
    }

  private:
    InputFile& in_;
    LineFields lines_;
    std::size_t next_ = 0;
    const PlyElement* element_ = nullptr;
};

std::uint32_t read_unsigned(const InputFile& in, ValueSource& src, PlyScalar type, const char* what) {
    const double v = src.next(type);
    if (!(v >= 0 && v <= 4294967295.0 && v == std::floor(v)))
        in.fail(std::string("invalid ") + what + " " + std::to_string(v));
    return static_cast<std::uint32_t>(v);
}

std::optional<std::size_t> face_index_list(const PlyElement& face) {
    for (const char* name : {"vertex_indices", "vertex_index"}) {
        if (const auto k = face.find(name); k && face.properties[*k].is_list) return k;
    }
    return std::nullopt;
}

// Rejects counts the body cannot hold before anything is allocated for them.
void check_declared_sizes(const InputFile& in, const PlyHeader& h) {
    std::uint64_t need = 0;
    for (const auto& e : h.elements) need += e.count * e.min_entry_bytes(h.format);
    const std::uint64_t slack = h.format == PlyFormat::ascii ? 1 : 0;  // last line may lack its newline
    if (need > in.remaining() + slack) {
        in.fail("truncated: the header declares at least " + std::to_string(need) + " bytes of data, only " +
                std::to_string(in.remaining()) + " follow it");
    }
}

}  // namespace

MeshData read_ply_mesh(const std::string& path) {
    InputFile in(path);
    const PlyHeader h = read_ply_header(in);
    const auto vi = h.find("vertex");
    if (!vi) in.fail("PLY file has no 'vertex' element");
    const PlyElement& ve = h.elements[*vi];
    if (const PlyProperty* list = ve.first_list()) {
        in.fail("list property '" + list->name + "' on the vertex element is not supported");
    }
    // Slot in the 6-float vertex record per vertex property; -1 = not used.
    std::vector<int> slot(ve.properties.size(), -1);
    const char* names[6] = {"x", "y", "z", "nx", "ny", "nz"};
    for (int s = 0; s < 6; ++s) {
        const auto k = ve.find(names[s]);
        if (k) slot[*k] = s;
        if (!k && s < 3) in.fail(std::string("vertex element has no '") + names[s] + "' property");
    }
    const auto fi = h.find("face");
    std::optional<std::size_t> face_list;
    if (fi) {
        face_list = face_index_list(h.elements[*fi]);
        if (!face_list && h.elements[*fi].count > 0)
            in.fail("face element has no 'vertex_indices' list property");
    }
    check_declared_sizes(in, h);

    std::unique_ptr<ValueSource> src;
    if (h.format == PlyFormat::ascii) {
        in.require_text_size("ASCII PLY");
        src = std::make_unique<AsciiSource>(in);
    } else {
        src = std::make_unique<BinarySource>(in, h.big_endian());
    }

    MeshData m;
    m.vertices6.assign(6 * ve.count, 0.0f);
    if (fi) m.indices.reserve(3 * h.elements[*fi].count);
    const std::size_t last = fi ? std::max(*vi, *fi) : *vi;  // later elements are not needed
    for (std::size_t ei = 0; ei <= last; ++ei) {
        const PlyElement& e = h.elements[ei];
        const bool is_vertex = ei == *vi, is_face = fi && ei == *fi;
        for (std::uint64_t i = 0; i < e.count; ++i) {
            src->begin_entry(e, i);
            for (std::size_t k = 0; k < e.properties.size(); ++k) {
                const PlyProperty& p = e.properties[k];
                if (!p.is_list) {
                    const double v = src->next(p.type);
                    if (is_vertex && slot[k] >= 0)
                        m.vertices6[6 * i + static_cast<std::size_t>(slot[k])] = narrow_coordinate(v);
                    continue;
                }
                const std::uint32_t n = read_unsigned(in, *src, p.count_type, "list length");
                const bool indices = is_face && k == *face_list;
                if (indices && n != 3) {
                    in.fail("face " + std::to_string(i) + " has " + std::to_string(n) +
                            " vertices; only triangles are supported");
                }
                for (std::uint32_t j = 0; j < n; ++j) {
                    if (indices) {
                        m.indices.push_back(read_unsigned(in, *src, p.type, "vertex index"));
                    } else {
                        src->next(p.type);
                    }
                }
            }
            src->end_entry();
        }
    }
    for (std::size_t k = 0; k < m.indices.size(); ++k) {
        if (m.indices[k] >= ve.count) {
            in.fail("face " + std::to_string(k / 3) + " references vertex " + std::to_string(m.indices[k]) +
                    " but there are " + std::to_string(ve.count) + " vertices");
        }
    }
    return m;
}

}  // namespace rivulet::io
