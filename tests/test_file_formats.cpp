// Particle and mesh file formats: round trips, hand-written fixtures in every supported variant, and the
// error message for each kind of bad input. Fixtures are generated into a temp dir.
#include <gtest/gtest.h>

#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "support/test_support.h"
#include "systems/io/mesh_io.h"
#include "systems/io/particle_io.h"
#include "systems/io/sequence_pattern.h"

namespace rivulet {
namespace {

namespace fs = std::filesystem;

std::string write_file(const std::string& name, const std::string& bytes) {
    const std::string path = test::temp_path(name);
    std::ofstream f(path, std::ios::binary);
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return path;
}

template <class T>
void append_be(std::string& out, T value) {
    char b[sizeof(T)];
    std::memcpy(b, &value, sizeof(T));
    if constexpr (std::endian::native == std::endian::little) {
        for (std::size_t i = 0; i < sizeof(T); ++i) out += b[sizeof(T) - 1 - i];
    } else {
        out.append(b, sizeof(T));
    }
}

template <class T>
void append_le(std::string& out, T value) {
    char b[sizeof(T)];
    std::memcpy(b, &value, sizeof(T));
    if constexpr (std::endian::native == std::endian::little) {
        out.append(b, sizeof(T));
    } else {
        for (std::size_t i = 0; i < sizeof(T); ++i) out += b[sizeof(T) - 1 - i];
    }
}

// Runs `fn`, expects FileFormatError, and checks every fragment appears in the message.
void expect_error(const std::function<void()>& fn, std::initializer_list<std::string> fragments) {
    try {
        fn();
        ADD_FAILURE() << "expected FileFormatError";
    } catch (const FileFormatError& e) {
        const std::string msg = e.what();
        for (const auto& f : fragments)
            EXPECT_NE(msg.find(f), std::string::npos) << "'" << f << "' not in: " << msg;
    }
}

void expect_read_error(const std::string& path, std::initializer_list<std::string> fragments) {
    expect_error([&] { read_particles(path); }, fragments);
}

void expect_cloud(const ParticleCloud& c, const std::vector<float>& xyz) {
    ASSERT_EQ(c.size() * 3, xyz.size());
    for (std::size_t i = 0; i < c.size(); ++i) {
        EXPECT_EQ(c.x[i], xyz[3 * i]) << i;
        EXPECT_EQ(c.y[i], xyz[3 * i + 1]) << i;
        EXPECT_EQ(c.z[i], xyz[3 * i + 2]) << i;
    }
}

const char* kAsciiHeader =
    "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float "
    "z\nend_header\n";

// ---------------------------------------------------------------- particle round trips and fixtures

TEST(ParticleIo, BinaryPlyRoundTripIsExact) {
    std::vector<float> x, y, z;
    for (int i = 0; i < 100000; ++i) {
        x.push_back(static_cast<float>(i) * 0.001f + 1e-7f);
        y.push_back(-static_cast<float>(i) / 3.0f);
        z.push_back(std::nextafter(static_cast<float>(i % 97), 1e9f));
    }
    x[5] = std::numeric_limits<float>::denorm_min();
    y[6] = std::numeric_limits<float>::max();
    const std::string path = test::temp_path("roundtrip.ply");
    write_particles_ply(path, x, y, z);
    const ParticleCloud c = read_particles(path);
    EXPECT_EQ(c.x, x);
    EXPECT_EQ(c.y, y);
    EXPECT_EQ(c.z, z);
}

TEST(ParticleIo, ExtensionIsCaseInsensitive) {
    const std::vector<float> v = {1.5f};
    const std::string path = test::temp_path("upper.PLY");
    write_particles_ply(path, v, v, v);
    expect_cloud(read_particles(path), {1.5f, 1.5f, 1.5f});
}

TEST(ParticleIo, AsciiPly) {
    const auto path =
        write_file("ascii.ply",
                   "ply\r\nformat ascii 1.0\r\ncomment hand written\r\nelement vertex 3\r\n"
                   "property float x\r\nproperty float y\r\nproperty float z\r\nproperty int id\r\n"
                   "end_header\r\n1 2 3 7\r\n-4.5 +5e-1 6e2 8\r\n\r\n0.1 0.2 0.3 9");
    expect_cloud(read_particles(path), {1, 2, 3, -4.5f, 0.5f, 600, 0.1f, 0.2f, 0.3f});
}

TEST(ParticleIo, BigEndianPlyWithDoublesExtraPropertyAndFaces) {
    std::string s =
        "ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty uchar flag\nproperty float64 z\n"
        "property double y\nproperty double x\nproperty uint8 alpha\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n";
    const double v[2][3] = {{1.25, -2.5, 1e-3}, {100.0, 0.1, -7.0}};
    for (const auto& p : v) {
        s += '\x01';
        append_be(s, p[2]);
        append_be(s, p[1]);
        append_be(s, p[0]);
        s += '\xff';
    }
    s += '\x03';
    for (std::int32_t i : {0, 1, 1}) append_be(s, i);
    const auto path = write_file("be.ply", s);
    expect_cloud(read_particles(path),
                 {1.25f, -2.5f, static_cast<float>(1e-3), 100.0f, static_cast<float>(0.1), -7.0f});
}

TEST(ParticleIo, BigEndianFloatsAmongOtherProperties) {
    std::string s =
        "ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty float z\nproperty short id\n"
        "property float x\nproperty float y\nproperty double w\nend_header\n";
    for (int i = 0; i < 2; ++i) {
        append_be(s, 3.5f + static_cast<float>(i)), append_be<std::int16_t>(s, 9), append_be(s, -1.25f);
        append_be(s, 2.0f * static_cast<float>(i)), append_be(s, 1e300);
    }
    expect_cloud(read_particles(write_file("be_float.ply", s)), {-1.25f, 0, 3.5f, -1.25f, 2, 4.5f});
}

TEST(ParticleIo, LittleEndianIntegerCoordinates) {
    std::string s =
        "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty short x\nproperty int32 y\n"
        "property ushort z\nend_header\n";
    append_le<std::int16_t>(s, -3), append_le<std::int32_t>(s, 70000), append_le<std::uint16_t>(s, 65535);
    append_le<std::int16_t>(s, 4), append_le<std::int32_t>(s, -1), append_le<std::uint16_t>(s, 0);
    expect_cloud(read_particles(write_file("ints.ply", s)), {-3, 70000, 65535, 4, -1, 0});
}

TEST(ParticleIo, ScalarElementBeforeVertexIsSkipped) {
    std::string s =
        "ply\nformat binary_little_endian 1.0\nelement camera 1\nproperty float fov\nproperty uchar id\n"
        "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    append_le(s, 60.0f), s += '\x02';
    append_le(s, 1.0f), append_le(s, 2.0f), append_le(s, 3.0f);
    expect_cloud(read_particles(write_file("camera.ply", s)), {1, 2, 3});
}

TEST(ParticleIo, ListElementBeforeVertexIsRejected) {
    const auto path =
        write_file("face_first.ply",
                   "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
                   "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                   "end_header\n3 0 0 0\n1 2 3\n");
    expect_read_error(path, {"face_first.ply", "precedes 'vertex'", "vertex_indices"});
}

TEST(ParticleIo, XyzWithCommentsAndExtraColumns) {
    const auto path = write_file(
        "cloud.xyz", "# x y z id\n\n1 2 3 42 extra\n  # indented comment\n\t4.5\t-5  6e-1\n7 8 9\r\n");
    expect_cloud(read_particles(path), {1, 2, 3, 4.5f, -5, 0.6f, 7, 8, 9});
}

TEST(ParticleIo, VtkAscii) {
    const auto path = write_file("pts.vtk",
                                 "# vtk DataFile Version 3.0\nparticles\nASCII\nDATASET POLYDATA\n"
                                 "POINTS 3 float\n0 1 2 3 4 5\n6\n7 8\nVERTICES 3 6\n1 0\n1 1\n1 2\n");
    expect_cloud(read_particles(path), {0, 1, 2, 3, 4, 5, 6, 7, 8});
}

TEST(ParticleIo, VtkBinaryFloatAndDouble) {
    std::string f =
        "# vtk DataFile Version 4.2\nbinary test\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 2 float\n";
    for (float v : {1.5f, -2.0f, 3.25f, 4.0f, 5.0f, -6.5f}) append_be(f, v);
    f += "\nCELLS 0 0\n";
    expect_cloud(read_particles(write_file("bin_f.vtk", f)), {1.5f, -2.0f, 3.25f, 4.0f, 5.0f, -6.5f});

    std::string d = "# vtk DataFile Version 3.0\nbinary test\nBINARY\nDATASET POLYDATA\nPOINTS 1 double\n";
    for (double v : {0.5, 0.25, -0.125}) append_be(d, v);
    expect_cloud(read_particles(write_file("bin_d.vtk", d)), {0.5f, 0.25f, -0.125f});
}

TEST(ParticleIo, MillionParticlesReadQuickly) {
    const std::size_t n = 1'000'000;
    std::vector<float> x(n), y(n), z(n);
    for (std::size_t i = 0; i < n; ++i)
        x[i] = static_cast<float>(i), y[i] = 1.0f, z[i] = -static_cast<float>(i);
    const std::string path = test::temp_path("million.ply");
    write_particles_ply(path, x, y, z);
    const auto t0 = std::chrono::steady_clock::now();
    const ParticleCloud c = read_particles(path);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(c.x, x);
    EXPECT_EQ(c.z, z);
    EXPECT_LT(ms, 2000.0);  // generous: guards against per-value syscalls, not a benchmark
    RecordProperty("read_ms", std::to_string(ms));
}

// ---------------------------------------------------------------- particle errors

TEST(ParticleErrors, MissingFile) {
    expect_read_error(test::temp_path("does_not_exist.ply"),
                      {"does_not_exist.ply", "cannot open", "No such file"});
}

TEST(ParticleErrors, EmptyFile) {
    for (const char* name : {"empty.ply", "empty.xyz", "empty.vtk"})
        expect_read_error(write_file(name, ""), {name, "empty"});
}

TEST(ParticleErrors, Directory) {
    const std::string dir = test::temp_path("a_dir.ply");
    fs::create_directories(dir);
    expect_read_error(dir, {"a_dir.ply", "directory"});
}

TEST(ParticleErrors, UnknownExtension) {
    expect_read_error(write_file("cloud.csv", "1,2,3\n"),
                      {"cloud.csv", "unknown particle file extension", ".csv"});
    expect_read_error(write_file("noext", "1 2 3\n"), {"noext", "unknown particle file extension"});
}

TEST(ParticleErrors, WrongMagic) {
    expect_read_error(write_file("magic.ply", "PLX\nformat ascii 1.0\n"), {"magic.ply", "not a PLY file"});
    expect_read_error(write_file("magic2.ply", "plywood\n"), {"not a PLY file"});
    expect_read_error(write_file("magic.vtk", "hello\n"), {"magic.vtk", "not a legacy VTK file"});
}

TEST(ParticleErrors, UnknownFormatLine) {
    expect_read_error(write_file("fmt.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n"),
                      {"fmt.ply", "line 2", "unknown PLY format 'binary_middle_endian'"});
    expect_read_error(write_file("fmt2.ply", "ply\nelement vertex 1\nend_header\n"),
                      {"expected 'format' line"});
    expect_read_error(write_file("vtkfmt.vtk", "# vtk DataFile Version 3.0\nt\nTEXT\n"),
                      {"expected ASCII or BINARY"});
}

TEST(ParticleErrors, MissingEndHeader) {
    expect_read_error(write_file("noend.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"),
                      {"noend.ply", "no 'end_header'"});
}

TEST(ParticleErrors, MissingCoordinateProperty) {
    expect_read_error(
        write_file("nox.ply",
                   "ply\nformat ascii 1.0\nelement vertex 1\nproperty float y\nproperty float z\n"
                   "end_header\n1 2\n"),
        {"nox.ply", "no 'x' property"});
    expect_read_error(write_file("novertex.ply",
                                 "ply\nformat ascii 1.0\nelement point 1\nproperty float x\nend_header\n1\n"),
                      {"no 'vertex' element"});
}

TEST(ParticleErrors, ListPropertyOnVertex) {
    expect_read_error(
        write_file("list.ply",
                   "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                   "property float z\nproperty list uchar float extra\nend_header\n1 2 3 1 4\n"),
        {"list.ply", "list property 'extra'", "vertex"});
}

TEST(ParticleErrors, UnknownPropertyType) {
    expect_read_error(
        write_file("type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\nend_header\n"),
        {"line 4", "unknown property type 'half'"});
}

TEST(ParticleErrors, TruncatedBinary) {
    std::string s =
        "ply\nformat binary_little_endian 1.0\nelement vertex 100\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n";
    s.append(800, '\0');
    expect_read_error(write_file("trunc.ply", s),
                      {"trunc.ply", "truncated binary vertex data: expected 1200 bytes, got 800"});

    std::string v = "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET POLYDATA\nPOINTS 10 float\n";
    v.append(100, '\0');
    expect_read_error(write_file("trunc.vtk", v),
                      {"truncated binary point data: expected 120 bytes, got 100"});
}

TEST(ParticleErrors, TruncatedAscii) {
    expect_read_error(write_file("trunc_ascii.ply", std::string(kAsciiHeader) + "1 2 3\n"),
                      {"trunc_ascii.ply", "truncated ascii vertex data"});
    expect_read_error(
        write_file("trunc_ascii.vtk",
                   "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n1 2 3 4 5\n"),
        {"truncated ascii point data"});
}

TEST(ParticleErrors, WrongColumnCountNamesLine) {
    expect_read_error(write_file("cols.ply", std::string(kAsciiHeader) + "1.0 2.0 3.0\n4.0 5.0\n"),
                      {"cols.ply", "line 9", "expected 3 values per vertex, got 2"});
    expect_read_error(write_file("word.ply", std::string(kAsciiHeader) + "1 2 3\n4 5 six\n"),
                      {"line 9", "'six' is not a number"});
}

TEST(ParticleErrors, NanCoordinateInEachFormat) {
    expect_read_error(write_file("nan.xyz", "0 0 0\n1 nan 1\n"),
                      {"nan.xyz", "non-finite coordinate at particle 1"});
    expect_read_error(write_file("nan_ascii.ply", std::string(kAsciiHeader) + "0 0 0\n1 1 inf\n"),
                      {"non-finite coordinate at particle 1"});
    expect_read_error(
        write_file("nan.vtk",
                   "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 NaN 0 0\n"),
        {"non-finite coordinate at particle 1"});
    const std::vector<float> x = {0, 1, 2}, y = {0, std::numeric_limits<float>::quiet_NaN(), 0},
                             z = {0, 0, 0};
    const std::string bin = test::temp_path("nan_bin.ply");
    write_particles_ply(bin, x, y, z);
    expect_read_error(bin, {"nan_bin.ply", "non-finite coordinate at particle 1"});
    // A double beyond float range cannot become a float coordinate.
    expect_read_error(write_file("huge.xyz", "1e300 0 0\n"), {"non-finite coordinate at particle 0"});
}

TEST(ParticleErrors, ZeroParticles) {
    const std::string ply = test::temp_path("zero.ply");
    write_particles_ply(ply, {}, {}, {});
    expect_read_error(ply, {"zero.ply", "no particles"});
    expect_read_error(write_file("zero.xyz", "# only a comment\n\n"), {"zero.xyz", "no particles"});
    expect_read_error(
        write_file("zero.vtk", "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 0 float\n"),
        {"no particles"});
}

TEST(ParticleErrors, XyzGarbageNamesLine) {
    expect_read_error(write_file("garbage.xyz", "1 2 3\n4 5 6\n7 eight 9\n"),
                      {"garbage.xyz", "line 3", "'eight' is not a number"});
    expect_read_error(write_file("short.xyz", "1 2 3\n\n4 5\n"), {"line 3", "expected at least 3 numbers"});
    expect_read_error(write_file("partial.xyz", "1 2 3\n1.5x 2 3\n"), {"line 2", "'1.5x' is not a number"});
}

TEST(ParticleErrors, HugeVertexCountIsRejectedWithoutAllocating) {
    expect_read_error(
        write_file("huge.ply",
                   "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
                   "property float y\nproperty float z\nend_header\n\x01\x02\x03"),
        {"huge.ply", "4000000000", "limit"});
    // Under the limit but far more than the file holds: caught by the size check, not by allocation.
    expect_read_error(
        write_file("big.ply",
                   "ply\nformat binary_little_endian 1.0\nelement vertex 400000000\nproperty float x\n"
                   "property float y\nproperty float z\nend_header\n\x01\x02\x03"),
        {"truncated binary vertex data: expected 4800000000 bytes, got 3"});
    expect_read_error(write_file("big_ascii.ply",
                                 "ply\nformat ascii 1.0\nelement vertex 400000000\nproperty float x\n"
                                 "property float y\nproperty float z\nend_header\n1 2 3\n"),
                      {"truncated ascii vertex data"});
    expect_read_error(
        write_file("huge.vtk",
                   "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET POLYDATA\nPOINTS 99999999999 float\n"),
        {"more than the limit"});
    expect_read_error(
        write_file("big.vtk",
                   "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET POLYDATA\nPOINTS 400000000 float\n"),
        {"truncated binary point data"});
}

TEST(ParticleErrors, BinaryGarbageIsNotMistakenForAHeader) {
    std::string junk(200000, '\x7f');
    expect_read_error(write_file("junk.ply", "ply\n" + junk), {"junk.ply", "line 2"});
    expect_read_error(write_file("junk.xyz", junk), {"junk.xyz"});
}

TEST(ParticleErrors, VtkUnsupportedDataset) {
    expect_read_error(
        write_file("grid.vtk", "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\n"),
        {"unsupported DATASET 'STRUCTURED_POINTS'"});
    expect_read_error(
        write_file("int.vtk",
                   "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 1 int\n1 2 3\n"),
        {"unsupported POINTS data type 'int'"});
}

TEST(ParticleErrors, WriterRejectsMismatchedSpans) {
    const std::vector<float> a = {1, 2}, b = {1};
    expect_error([&] { write_particles_ply(test::temp_path("mismatch.ply"), a, b, a); },
                 {"different lengths"});
}

TEST(ParticleErrors, WriterReportsUnopenablePath) {
    const std::vector<float> a = {1};
    expect_error([&] { write_particles_ply("/nonexistent_dir_rivulet/p.ply", a, a, a); },
                 {"/nonexistent_dir_rivulet/p.ply", "cannot open for writing", "No such file"});
}

// ---------------------------------------------------------------- meshes

struct Cube {
    std::vector<float> v6;
    std::vector<std::uint32_t> idx;
};

Cube make_cube() {
    Cube c;
    for (int i = 0; i < 8; ++i) {
        const float p[3] = {static_cast<float>(i & 1), static_cast<float>((i >> 1) & 1),
                            static_cast<float>((i >> 2) & 1)};
        const float len = std::sqrt(3.0f);
        for (float q : p) c.v6.push_back(q * 0.1f + 0.0123456789f);
        for (float q : p) c.v6.push_back((2 * q - 1) / len);
    }
    c.idx = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
             2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    return c;
}

TEST(MeshIo, PlyRoundTripIsExact) {
    const Cube cube = make_cube();
    const std::string path = test::temp_path("cube.ply");
    write_mesh(path, cube.v6, cube.idx);
    const MeshData m = read_mesh(path);
    EXPECT_EQ(m.vertices6, cube.v6);
    EXPECT_EQ(m.indices, cube.idx);
    std::vector<float> positions;
    for (std::size_t i = 0; i < m.vertices6.size(); i += 6)
        positions.insert(positions.end(), &m.vertices6[i], &m.vertices6[i + 3]);
    EXPECT_EQ(test::count_open_edges(positions, m.indices), 0u);  // still a closed surface
}

TEST(MeshIo, ObjRoundTrip) {
    const Cube cube = make_cube();
    const std::string path = test::temp_path("cube.OBJ");
    write_mesh(path, cube.v6, cube.idx);
    const MeshData m = read_mesh(path);
    ASSERT_EQ(m.vertices6.size(), cube.v6.size());
    for (std::size_t i = 0; i < m.vertices6.size(); ++i) EXPECT_NEAR(m.vertices6[i], cube.v6[i], 1e-6f) << i;
    EXPECT_EQ(m.indices, cube.idx);
}

TEST(MeshIo, VtkIsWrittenAsBinaryPolydata) {
    const Cube cube = make_cube();
    const std::string path = test::temp_path("cube.vtk");
    write_mesh(path, cube.v6, cube.idx);
    std::ifstream f(path, std::ios::binary);
    std::string line;
    std::getline(f, line);
    EXPECT_TRUE(line.starts_with("# vtk DataFile Version"));
    std::getline(f, line);
    std::getline(f, line);
    EXPECT_EQ(line, "BINARY");
    std::getline(f, line);
    EXPECT_EQ(line, "DATASET POLYDATA");
    std::getline(f, line);
    EXPECT_EQ(line, "POINTS 8 float");
    std::string points(8 * 12, '\0');
    f.read(points.data(), static_cast<std::streamsize>(points.size()));
    std::getline(f, line);  // newline after binary block
    std::getline(f, line);
    EXPECT_EQ(line, "POLYGONS 12 48");
    std::string cells(12 * 16, '\0');
    f.read(cells.data(), static_cast<std::streamsize>(cells.size()));
    EXPECT_EQ(cells.substr(0, 4), std::string("\0\0\0\x03", 4));
    std::getline(f, line);
    std::getline(f, line);
    EXPECT_EQ(line, "POINT_DATA 8");
    std::getline(f, line);
    EXPECT_EQ(line, "NORMALS normals float");
    // The point block is the same binary layout the particle reader parses.
    const ParticleCloud pts = read_particles(path);
    ASSERT_EQ(pts.size(), 8u);
    EXPECT_EQ(pts.x[7], cube.v6[42]);
    EXPECT_EQ(pts.z[7], cube.v6[44]);
}

TEST(MeshIo, ReadsForeignObjAndAsciiPly) {
    const auto obj =
        write_file("quad.obj",
                   "# foreign\nmtllib x.mtl\no quad\nv 0 0 0\nv 1 0 0 1.0\nv 1 1 0\nv 0 1 0\nvt 0 0\n"
                   "vn 0 0 1\ns off\nf 1/1/1 2/1/1 3/1/1\nf -4 -2 -1\n");
    const MeshData m = read_mesh(obj);
    EXPECT_EQ(m.vertex_count(), 4u);
    EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
    EXPECT_EQ(m.vertices6[5], 1.0f);   // vertex 0 got the face's normal
    EXPECT_EQ(m.vertices6[23], 0.0f);  // vertex 3 has none

    const auto ply = write_file(
        "tri.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nproperty uchar red\nelement face 1\nproperty list uchar int vertex_index\n"
        "property uchar material\nend_header\n0 0 0 255\n1 0 0 0\n0 1 0 9\n3 0 1 2 7\n");
    const MeshData t = read_mesh(ply);
    EXPECT_EQ(t.vertices6, (std::vector<float>{0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0}));
    EXPECT_EQ(t.indices, (std::vector<std::uint32_t>{0, 1, 2}));
}

TEST(MeshIo, EmptyMeshRoundTrips) {
    for (const char* name : {"empty_mesh.obj", "empty_mesh.ply"}) {
        const std::string path = test::temp_path(name);
        write_mesh(path, {}, {});
        const MeshData m = read_mesh(path);
        EXPECT_TRUE(m.vertices6.empty());
        EXPECT_TRUE(m.indices.empty());
    }
}

TEST(MeshErrors, WriterRejectsBadInput) {
    const Cube cube = make_cube();
    std::vector<std::uint32_t> bad = cube.idx;
    bad[7] = 8;
    const std::string path = test::temp_path("bad.obj");
    expect_error([&] { write_mesh(path, cube.v6, bad); },
                 {"bad.obj", "triangle 2 references vertex 8", "8 vertices"});
    EXPECT_FALSE(fs::exists(path));
    expect_error([&] { write_mesh(path, std::span(cube.v6).first(10), {}); }, {"not a multiple of 6"});
    expect_error([&] { write_mesh(path, cube.v6, std::span(cube.idx).first(4)); }, {"not a multiple of 3"});
    expect_error([&] { write_mesh(test::temp_path("mesh.stl"), cube.v6, cube.idx); },
                 {"unknown mesh file extension '.stl'"});
}

TEST(MeshErrors, WriterReportsDiskFull) {
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
    const Cube cube = make_cube();
    std::vector<float> big;
    for (int i = 0; i < 20000; ++i) big.insert(big.end(), cube.v6.begin(), cube.v6.end());
    const std::string link = test::temp_path("full.ply");
    fs::remove(link);
    fs::create_symlink("/dev/full", link);
    expect_error([&] { write_mesh(link, big, cube.idx); }, {"full.ply", "No space left on device"});
}

TEST(MeshErrors, ReaderRejectsBadFiles) {
    expect_error([&] { read_mesh(write_file("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n")); },
                 {"range.obj", "line 4", "vertex index 4 out of range"});
    expect_error(
        [&] { read_mesh(write_file("quad_face.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4\n")); },
        {"line 5", "only triangles"});
    expect_error([&] { read_mesh(write_file("nan.obj", "v 0 nan 0\n")); },
                 {"nan.obj", "non-finite position at vertex 0"});
    expect_error(
        [&] {
            read_mesh(write_file(
                "range.ply",
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"));
        },
        {"range.ply", "face 0 references vertex 3"});
    expect_error(
        [&] {
            read_mesh(write_file(
                "quad.ply",
                "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                "0 0 0\n1 0 0\n0 1 0\n1 1 0\n4 0 1 2 3\n"));
        },
        {"face 0 has 4 vertices"});
    std::string s =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 2\nproperty list uchar uint vertex_indices\nend_header\n";
    s.append(36, '\0');
    s += '\x03';
    s.append(12, '\0');
    s += '\x03';
    s.append(5, '\0');
    expect_error([&] { read_mesh(write_file("trunc_mesh.ply", s)); },
                 {"trunc_mesh.ply", "truncated binary data in element 'face'"});
    expect_error(
        [&] {
            read_mesh(write_file(
                "huge_mesh.ply",
                "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                "property float z\nelement face 400000000\nproperty list uchar uint "
                "vertex_indices\nend_header\n"));
        },
        {"truncated: the header declares"});
    expect_error([&] { read_mesh(write_file("mesh.vtk", "# vtk DataFile Version 3.0\n")); },
                 {"unsupported mesh file extension"});
}

// ---------------------------------------------------------------- sequences

std::string make_sequence_dir(const std::string& name, std::initializer_list<const char*> files) {
    const std::string dir = test::temp_path(name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    for (const char* f : files) std::ofstream(dir + "/" + f) << "x";
    return dir;
}

TEST(Sequence, SortsNumerically) {
    const std::string dir =
        make_sequence_dir("seq1", {"frame_1.ply", "frame_2.ply", "frame_10.ply", "frame_x.ply", "frame_.ply",
                                   "frame_3.ply.bak", "other_4.ply"});
    fs::create_directories(dir + "/frame_5.ply");  // a directory is not a frame
    const auto frames = expand_sequence(dir + "/frame_{}.ply");
    ASSERT_EQ(frames.size(), 3u);
    EXPECT_EQ(frames[0].number, 1);
    EXPECT_EQ(frames[1].number, 2);
    EXPECT_EQ(frames[2].number, 10);
    EXPECT_EQ(frames[2].path, dir + "/frame_10.ply");
    EXPECT_EQ(frames[2].width, 2);
}

TEST(Sequence, KeepsZeroPaddingWidth) {
    const std::string dir = make_sequence_dir("seq2", {"frame_0001.ply", "frame_0002.ply", "frame_0010.ply"});
    const auto frames = expand_sequence(dir + "/frame_{}.ply");
    ASSERT_EQ(frames.size(), 3u);
    EXPECT_EQ(frames[2].number, 10);
    EXPECT_EQ(frames[2].width, 4);
    EXPECT_EQ(frames[0].path, dir + "/frame_0001.ply");
    EXPECT_EQ(sequence_output_path("out_{}.obj", frames[2].number, frames[2].width), "out_0010.obj");
}

TEST(Sequence, Errors) {
    const std::string dir = make_sequence_dir("seq3", {"frame_1.ply", "frame_01.ply"});
    expect_error([&] { expand_sequence(dir + "/nothing_{}.ply"); }, {"nothing_{}.ply", "no files match"});
    expect_error([&] { expand_sequence(dir + "/frame_{}.ply"); }, {"ambiguous frame number 1"});
    expect_error([&] { expand_sequence(dir + "/frame_1.ply"); }, {"no '{}'"});
    expect_error([&] { expand_sequence(dir + "/f_{}_{}.ply"); }, {"more than one"});
    expect_error([&] { expand_sequence(dir + "/missing_dir/f_{}.ply"); }, {"cannot list directory"});
    expect_error([&] { expand_sequence(dir + "_{}/f.ply"); }, {"must be in the file name"});
}

TEST(Sequence, OutputPathAndDetection) {
    EXPECT_EQ(sequence_output_path("out_{}.obj", 7, 4), "out_0007.obj");
    EXPECT_EQ(sequence_output_path("out_{}.obj", 7, 0), "out_7.obj");
    EXPECT_EQ(sequence_output_path("out_{}.obj", 12345, 3), "out_12345.obj");
    EXPECT_EQ(sequence_output_path("dir/{}", 3, 2), "dir/03");
    EXPECT_EQ(sequence_output_path("m{}.ply", -5, 3), "m-005.ply");
    expect_error([] { sequence_output_path("out.obj", 1, 0); }, {"no '{}'"});
    EXPECT_TRUE(is_sequence_pattern("frames/frame_{}.ply"));
    EXPECT_FALSE(is_sequence_pattern("frames/frame_1.ply"));
}

}  // namespace
}  // namespace rivulet
