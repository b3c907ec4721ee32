#include "systems/io/assimp_mesh.h"

#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <png.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace rivulet {
namespace {

constexpr std::size_t kMaxTriangles = 50'000'000;
constexpr std::uint32_t kMaxTextureSide = 16384;

[[noreturn]] void fail(const std::string& path, const std::string& why) {
    throw std::runtime_error("cannot read mesh '" + path + "': " + why);
}

// An RGB image, rows from the top.
struct Image {
    std::uint32_t width = 0, height = 0;
    std::vector<std::uint8_t> rgb;

    // Nearest texel, repeating outside [0, 1) as the formats' default wrap mode does.
    aiColor3D at(float u, float v) const {
        auto wrap = [](float t, std::uint32_t n) {
            const float f = t - std::floor(t);
            return std::min(n - 1, static_cast<std::uint32_t>(f * float(n)));
        };
        if (!std::isfinite(u) || !std::isfinite(v)) return {1, 1, 1};
        const std::size_t i = 3 * (std::size_t(wrap(1 - v, height)) * width + wrap(u, width));  // v up
        return {rgb[i] / 255.0f, rgb[i + 1] / 255.0f, rgb[i + 2] / 255.0f};
    }
};

std::optional<Image> finish_png(png_image& png) {
    png.format = PNG_FORMAT_RGB;
    if (png.width == 0 || png.height == 0 || png.width > kMaxTextureSide || png.height > kMaxTextureSide) {
        png_image_free(&png);
        return std::nullopt;
    }
    Image img{png.width, png.height, std::vector<std::uint8_t>(PNG_IMAGE_SIZE(png))};
    return img;
}

std::optional<Image> decode_png_memory(const void* data, std::size_t size) {
    png_image png;
    std::memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&png, data, size)) return std::nullopt;
    auto img = finish_png(png);
    if (img && !png_image_finish_read(&png, nullptr, img->rgb.data(), 0, nullptr)) return std::nullopt;
    return img;
}

std::optional<Image> decode_png_file(const std::string& file) {
    png_image png;
    std::memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&png, file.c_str())) return std::nullopt;
    auto img = finish_png(png);
    if (img && !png_image_finish_read(&png, nullptr, img->rgb.data(), 0, nullptr)) return std::nullopt;
    return img;
}

// The material's diffuse texture, when it can be had: embedded (raw texels, or a PNG) or a PNG file
// next to the model. Other compressed formats (JPEG, ...) are not decoded: the diffuse colour stands in.
std::optional<Image> diffuse_texture(const aiScene& scene, const aiMaterial& mat, const std::string& path) {
    aiString name;
    if (mat.GetTexture(aiTextureType_DIFFUSE, 0, &name) != AI_SUCCESS &&
        mat.GetTexture(aiTextureType_BASE_COLOR, 0, &name) != AI_SUCCESS)
        return std::nullopt;
    if (const aiTexture* tex = scene.GetEmbeddedTexture(name.C_Str())) {
        if (tex->mHeight == 0) return decode_png_memory(tex->pcData, tex->mWidth);  // compressed bytes
        if (tex->mWidth > kMaxTextureSide || tex->mHeight > kMaxTextureSide) return std::nullopt;
        Image img{tex->mWidth, tex->mHeight, {}};
        img.rgb.reserve(std::size_t(3) * tex->mWidth * tex->mHeight);
        for (std::size_t i = 0; i < std::size_t(tex->mWidth) * tex->mHeight; ++i)
            img.rgb.insert(img.rgb.end(), {tex->pcData[i].r, tex->pcData[i].g, tex->pcData[i].b});
        return img;  // aiTexel rows are stored from the top, like PNG
    }
    const std::filesystem::path file = std::filesystem::path(path).parent_path() / name.C_Str();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) return std::nullopt;
    return decode_png_file(file.string());
}

std::optional<aiColor3D> diffuse_colour(const aiMaterial& mat) {
    // Assimp makes up a material for files without any: "DefaultMaterial" (OBJ) or an unnamed one (PLY).
    aiString name;
    if (mat.Get(AI_MATKEY_NAME, name) != AI_SUCCESS || name.length == 0 ||
        std::strcmp(name.C_Str(), AI_DEFAULT_MATERIAL_NAME) == 0)
        return std::nullopt;
    aiColor4D c;
    if (mat.Get(AI_MATKEY_BASE_COLOR, c) == AI_SUCCESS || mat.Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS)
        return aiColor3D(c.r, c.g, c.b);
    return std::nullopt;
}

float unit(float v) {
    return std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
}

struct Merger {
    const aiScene& scene;
    const std::string& path;
    ColoredMesh out;
    std::vector<std::uint8_t> coloured;  // per vertex of out: whether a source gave it a colour
    std::size_t triangles = 0;

    void add(const aiMesh& mesh, const aiMatrix4x4& to_world) {
        if (!(mesh.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || mesh.mNumVertices == 0) return;
        for (unsigned f = 0; f < mesh.mNumFaces; ++f) triangles += mesh.mFaces[f].mNumIndices == 3;
        if (triangles > kMaxTriangles)
            fail(path, "more than " + std::to_string(kMaxTriangles) + " triangles");
        if (out.vertex_count() + mesh.mNumVertices > std::numeric_limits<std::uint32_t>::max())
            fail(path, "too many vertices");
        const auto base = static_cast<std::uint32_t>(out.vertex_count());
        for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
            const aiVector3D p = to_world * mesh.mVertices[v];
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                fail(path, "a vertex coordinate is not finite");
            out.positions.insert(out.positions.end(), {p.x, p.y, p.z});
        }
        for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
            const aiFace& face = mesh.mFaces[f];
            if (face.mNumIndices != 3) continue;
            for (int k = 0; k < 3; ++k) {
                if (face.mIndices[k] >= mesh.mNumVertices) fail(path, "a face index is out of range");
                out.indices.push_back(base + face.mIndices[k]);
            }
        }
        colour(mesh);
    }

    void colour(const aiMesh& mesh) {
        auto put = [&](aiColor3D c) {
            out.colors.insert(out.colors.end(), {unit(c.r), unit(c.g), unit(c.b)});
            coloured.push_back(1);
        };
        if (mesh.HasVertexColors(0)) {
            for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
                const aiColor4D& c = mesh.mColors[0][v];
                put({c.r, c.g, c.b});
            }
            return;
        }
        const aiMaterial* mat =
            mesh.mMaterialIndex < scene.mNumMaterials ? scene.mMaterials[mesh.mMaterialIndex] : nullptr;
        const std::optional<aiColor3D> tint = mat ? diffuse_colour(*mat) : std::nullopt;
        if (mat && mesh.HasTextureCoords(0)) {
            if (const auto img = diffuse_texture(scene, *mat, path)) {
                const aiColor3D k = tint.value_or(aiColor3D(1, 1, 1));
                for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
                    const aiColor3D t = img->at(mesh.mTextureCoords[0][v].x, mesh.mTextureCoords[0][v].y);
                    put({t.r * k.r, t.g * k.g, t.b * k.b});
                }
                return;
            }
        }
        for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
            if (tint) {
                put(*tint);
            } else {
                out.colors.insert(out.colors.end(), {1, 1, 1});
                coloured.push_back(0);
            }
        }
    }

    void walk(const aiNode& node, const aiMatrix4x4& parent) {
        const aiMatrix4x4 to_world = parent * node.mTransformation;
        for (unsigned i = 0; i < node.mNumMeshes; ++i)
            if (node.mMeshes[i] < scene.mNumMeshes) add(*scene.mMeshes[node.mMeshes[i]], to_world);
        for (unsigned i = 0; i < node.mNumChildren; ++i) walk(*node.mChildren[i], to_world);
    }
};

}  // namespace

ColoredMesh read_colored_mesh(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) fail(path, "no such file");
    Assimp::Importer importer;
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    // No normal generation: the voxelizer needs positions and colours only.
    const aiScene* scene =
        importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                    aiProcess_SortByPType | aiProcess_ValidateDataStructure);
    if (!scene || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !scene->mRootNode)
        fail(path, importer.GetErrorString());
    Merger m{*scene, path, {}, {}, 0};
    m.walk(*scene->mRootNode, aiMatrix4x4());
    if (m.out.indices.empty()) fail(path, "it has no triangles");
    if (std::none_of(m.coloured.begin(), m.coloured.end(), [](std::uint8_t c) { return c != 0; }))
        m.out.colors.clear();
    return std::move(m.out);
}

}  // namespace rivulet
