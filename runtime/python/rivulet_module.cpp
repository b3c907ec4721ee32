// `import rivulet`: the public API (include/rivulet) for Python and NumPy (docs/library.md). Positions
// come in as (N, 3) arrays, float32 C-contiguous ones without a copy; meshes and particles go out as new
// arrays the caller owns. The GIL is released while Rivulet works.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <optional>
#include <string>

#include "rivulet/rivulet.h"

namespace py = pybind11;

namespace {

using Points = py::array_t<float, py::array::c_style | py::array::forcecast>;

std::span<const float> xyz_of(const Points& points) {
    if (points.ndim() != 2 || points.shape(1) != 3)
        throw rivulet::Error("points must be an (N, 3) array, got shape (" + [&] {
            std::string s;
            for (py::ssize_t d = 0; d < points.ndim(); ++d)
                s += (d ? ", " : "") + std::to_string(points.shape(d));
            return s;
        }() + ")");
    return {points.data(), static_cast<std::size_t>(points.size())};
}

py::array_t<float> rows_of_three(const float* src, std::size_t rows, std::size_t stride) {
    py::array_t<float> out({static_cast<py::ssize_t>(rows), py::ssize_t{3}});
    float* dst = out.mutable_data();
    for (std::size_t i = 0; i < rows; ++i) std::memcpy(dst + 3 * i, src + stride * i, 3 * sizeof(float));
    return out;
}

rivulet::Method parse_method(const std::string& name) {
    if (name == "slices") return rivulet::Method::kSlices;
    if (name == "scan") return rivulet::Method::kScan;
    if (name == "volume") return rivulet::Method::kVolume;
    throw rivulet::Error("method must be 'slices', 'scan' or 'volume', got '" + name + "'");
}

// (vertices (V, 3), normals (V, 3), triangles (T, 3)), copied out of the extractor's workspace.
py::tuple mesh_arrays(const rivulet::MeshView& mesh) {
    const std::size_t v = mesh.vertex_count(), t = mesh.triangle_count();
    py::array_t<std::uint32_t> triangles({static_cast<py::ssize_t>(t), py::ssize_t{3}});
    std::memcpy(triangles.mutable_data(), mesh.indices.data(), mesh.indices.size_bytes());
    return py::make_tuple(rows_of_three(mesh.vertices.data(), v, 6),
                          rows_of_three(mesh.vertices.data() + 3, v, 6), triangles);
}

class PyExtractor {
  public:
    py::tuple extract(const Points& points, std::optional<float> radius, const std::string& method,
                      std::optional<float> voxel, std::optional<float> anisotropy,
                      std::optional<int> threads) {
        const std::span<const float> xyz = xyz_of(points);
        rivulet::SurfaceSettings s;
        s.method = parse_method(method);
        s.radius = radius.value_or(0.0f);
        s.voxel = voxel.value_or(0.0f);
        s.anisotropy = anisotropy.value_or(0.0f);
        s.threads = threads.value_or(0);
        rivulet::MeshView mesh;
        {
            py::gil_scoped_release unlocked;
            mesh = extractor_.extract(xyz, s);
        }
        return mesh_arrays(mesh);
    }

  private:
    rivulet::SurfaceExtractor extractor_;
};

// rivulet.simulate(...): each next() simulates one frame and returns its positions.
class Frames {
  public:
    Frames(const std::string& scene, int frames, std::optional<int> warmup, std::optional<int> threads)
        : frames_(frames) {
        if (frames < 0) throw rivulet::Error("frames must be at least 0, got " + std::to_string(frames));
        py::gil_scoped_release unlocked;
        sim_.emplace(scene, warmup.value_or(-1), threads.value_or(0));
    }
    py::array_t<float> next() {
        if (sim_->frame() >= static_cast<std::uint64_t>(frames_)) throw py::stop_iteration();
        {
            py::gil_scoped_release unlocked;
            sim_->step();
        }
        const rivulet::PositionsView p = sim_->positions();
        py::array_t<float> out({static_cast<py::ssize_t>(p.size()), py::ssize_t{3}});
        float* dst = out.mutable_data();
        for (std::size_t i = 0; i < p.size(); ++i)
            dst[3 * i] = p.x[i], dst[3 * i + 1] = p.y[i], dst[3 * i + 2] = p.z[i];
        return out;
    }
    const rivulet::Simulation& simulation() const { return *sim_; }

  private:
    std::optional<rivulet::Simulation> sim_;
    int frames_;
};

}  // namespace

PYBIND11_MODULE(rivulet, m) {
    m.doc() =
        "Rivulet: fluid surfaces from particles (marching slices, sphere scan conversion, density volume)";
    m.attr("__version__") = std::to_string(rivulet::kVersionMajor) + "." +
                            std::to_string(rivulet::kVersionMinor) + "." +
                            std::to_string(rivulet::kVersionPatch);
    py::register_exception<rivulet::Error>(m, "Error", PyExc_RuntimeError);

    py::class_<PyExtractor>(m, "SurfaceExtractor",
                            "Keeps its workspace between calls: extracting frame after frame reuses it.")
        .def(py::init<>())
        .def("extract", &PyExtractor::extract, py::arg("points"), py::arg("radius") = py::none(),
             py::arg("method") = "slices", py::arg("voxel") = py::none(), py::arg("anisotropy") = py::none(),
             py::arg("threads") = py::none(),
             "(vertices, normals, triangles) of the surface of points, an (N, 3) array; as reconstruct().");

    m.def(
        "reconstruct",
        [](const Points& points, std::optional<float> radius, const std::string& method,
           std::optional<float> voxel, std::optional<float> anisotropy, std::optional<int> threads) {
            PyExtractor extractor;
            return extractor.extract(points, radius, method, voxel, anisotropy, threads);
        },
        py::arg("points"), py::arg("radius") = py::none(), py::arg("method") = "slices",
        py::arg("voxel") = py::none(), py::arg("anisotropy") = py::none(), py::arg("threads") = py::none(),
        "The surface of points, an (N, 3) float32 or float64 array, as (vertices (V, 3) float32, normals (V, "
        "3) "
        "float32, triangles (T, 3) uint32), triangles counter-clockwise seen from outside.\n"
        "radius: particle radius (None: estimated from the points); method: 'slices', 'scan' or 'volume';\n"
        "voxel: slices cube edge / volume lattice spacing (None: automatic); anisotropy: slices' "
        "anisotropic\n"
        "kernels, longest over shortest axis in [1, 4] (None: spheres); threads: workers (None: all).");

    m.def(
        "read_particles",
        [](const std::string& path) {
            rivulet::Particles p;
            {
                py::gil_scoped_release unlocked;
                p = rivulet::load_particles(path);
            }
            return rows_of_three(p.xyz.data(), p.size(), 3);
        },
        py::arg("path"), "Positions of a .ply, .xyz or .vtk particle file as an (N, 3) float32 array.");

    m.def(
        "write_particles",
        [](const std::string& path, const Points& points) {
            const std::span<const float> xyz = xyz_of(points);
            py::gil_scoped_release unlocked;
            rivulet::save_particles(path, xyz);
        },
        py::arg("path"), py::arg("points"), "Writes an (N, 3) array as a binary PLY of float x, y, z.");

    m.def(
        "mesh_hash",
        [](const Points& vertices, const Points& normals,
           const py::array_t<std::uint32_t, py::array::c_style | py::array::forcecast>& triangles) {
            const std::span<const float> v = xyz_of(vertices), n = xyz_of(normals);
            if (v.size() != n.size()) throw rivulet::Error("vertices and normals differ in length");
            std::vector<float> interleaved(2 * v.size());
            for (std::size_t i = 0; i < v.size() / 3; ++i) {
                std::memcpy(&interleaved[6 * i], &v[3 * i], 3 * sizeof(float));
                std::memcpy(&interleaved[6 * i + 3], &n[3 * i], 3 * sizeof(float));
            }
            const std::span<const std::uint32_t> t{triangles.data(),
                                                   static_cast<std::size_t>(triangles.size())};
            return rivulet::mesh_hash(rivulet::MeshView{interleaved, t, 0});
        },
        py::arg("vertices"), py::arg("normals"), py::arg("triangles"),
        "The hash `rivulet mesh --json` prints for the same mesh (XXH3-64 of its buffers).");

    py::class_<Frames>(m, "Frames", "The frames of rivulet.simulate(): an iterator of (N, 3) float32 arrays.")
        .def("__iter__", [](Frames& f) -> Frames& { return f; })
        .def("__next__", &Frames::next)
        .def_property_readonly("particle_radius",
                               [](const Frames& f) { return f.simulation().particle_radius(); })
        .def_property_readonly("frame_rate", [](const Frames& f) { return f.simulation().frame_rate(); })
        .def_property_readonly("name", [](const Frames& f) { return f.simulation().name(); });

    m.def(
        "simulate",
        [](const std::string& scene, int frames, std::optional<int> warmup, std::optional<int> threads) {
            return Frames(scene, frames, warmup, threads);
        },
        py::arg("scene"), py::arg("frames"), py::arg("warmup") = py::none(), py::arg("threads") = py::none(),
        "Simulates a built-in scene (rivulet.scenes()) or a scene file for `frames` frames after its "
        "warm-up\n"
        "(warmup: None for the scene's own), yielding each frame's positions as an (N, 3) float32 array.");

    m.def("scenes", &rivulet::Simulation::builtin_scenes, "The built-in scenes' names.");

    m.def(
        "replay",
        [](const std::string& path, int frames, std::optional<int> threads) {
            rivulet::ReplayReport r;
            {
                py::gil_scoped_release unlocked;
                r = rivulet::replay(path, frames, threads.value_or(0));
            }
            py::dict d;
            d["scene"] = r.scene, d["method"] = r.method, d["recorded"] = r.recorded, d["frames"] = r.frames;
            d["identical"] = r.identical;
            if (!r.identical) {
                d["frame"] = r.frame, d["simulation_frame"] = r.simulation_frame, d["buffer"] = r.buffer;
                d["recorded_hash"] = r.recorded_hash, d["replayed_hash"] = r.replayed_hash;
            }
            return d;
        },
        py::arg("path"), py::arg("frames") = 0, py::arg("threads") = py::none(),
        "Re-runs a recording (`rivulet run --record`) as `rivulet replay` does: its first `frames` recorded\n"
        "frames (0: all). Returns a dict: scene, method, recorded, frames, identical, and where it is not\n"
        "identical the first differing frame, simulation_frame, buffer, recorded_hash and replayed_hash.");
}
