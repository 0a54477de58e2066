// The glTF export (docs/format.md "glTF export: SHREFRACT_sh_refraction"), through tinygltf.
#include "common/gltf/gltf_export.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include <glm/gtc/packing.hpp>

#include "common/error.h"
#include "common/format_internal.h"
#include "common/gltf_model.h"
#include "common/png.h"
#include "common/prefilter.h"
#include "common/sh.h"

namespace shrefract {

namespace {

constexpr const char* kExtension = "SHREFRACT_sh_refraction";
// 2: a refraction names its basis ("sh" or "grid", docs/format.md "glTF export"); version 1 had SH
// only. Readers of 1 refuse 2, so none reads a grid's weights as SH.
constexpr int kExtensionVersion = 2;

std::vector<uint8_t> glbBytes(tinygltf::Model& model);

// nlohmann's JSON as tinygltf's Value (its extension maps hold Values).
tinygltf::Value toValue(const nlohmann::json& j) {
    if (j.is_object()) {
        tinygltf::Value::Object o;
        for (auto it = j.begin(); it != j.end(); ++it) o[it.key()] = toValue(it.value());
        return tinygltf::Value(std::move(o));
    }
    if (j.is_array()) {
        tinygltf::Value::Array a;
        for (const auto& v : j) a.push_back(toValue(v));
        return tinygltf::Value(std::move(a));
    }
    if (j.is_boolean()) return tinygltf::Value(j.get<bool>());
    if (j.is_number_integer()) return tinygltf::Value(j.get<int>());
    if (j.is_number()) return tinygltf::Value(j.get<double>());
    if (j.is_string()) return tinygltf::Value(j.get<std::string>());
    return tinygltf::Value();
}

// The one binary buffer of the GLB, filled view by view (each view 4-byte aligned).
class BinaryBuffer {
public:
    // fresh: a model without buffers gets its buffer 0; otherwise views go to the end of buffer 0.
    explicit BinaryBuffer(tinygltf::Model& model, bool fresh = true) : model_(model) {
        if (fresh) model_.buffers.emplace_back();
    }
    int view(const void* data, size_t bytes, int target = 0) {
        std::vector<unsigned char>& b = model_.buffers[0].data;
        b.resize((b.size() + 3) / 4 * 4, 0);
        tinygltf::BufferView v;
        v.buffer = 0;
        v.byteOffset = b.size();
        v.byteLength = bytes;
        v.target = target;
        const auto* p = static_cast<const unsigned char*>(data);
        b.insert(b.end(), p, p + bytes);
        model_.bufferViews.push_back(v);
        return static_cast<int>(model_.bufferViews.size()) - 1;
    }
    int accessor(int view, int componentType, int type, size_t count, std::vector<double> lo = {},
                 std::vector<double> hi = {}) {
        tinygltf::Accessor a;
        a.bufferView = view;
        a.componentType = componentType;
        a.type = type;
        a.count = count;
        a.minValues = std::move(lo);
        a.maxValues = std::move(hi);
        model_.accessors.push_back(a);
        return static_cast<int>(model_.accessors.size()) - 1;
    }

private:
    tinygltf::Model& model_;
};

// A glass material plain glTF viewers understand (transmission, IOR, and absorption as volume
// attenuation over one object-space unit: attenuationColor = exp(-kappa)).
int glassMaterial(tinygltf::Model& model, float ior, glm::vec3 kappa, std::vector<std::string>& used) {
    tinygltf::Material m;
    m.name = "glass";
    m.pbrMetallicRoughness.metallicFactor = 0.0;
    m.pbrMetallicRoughness.roughnessFactor = 0.0;
    m.extensions["KHR_materials_transmission"] = toValue({{"transmissionFactor", 1.0}});
    m.extensions["KHR_materials_ior"] = toValue({{"ior", ior}});
    used.insert(used.end(), {"KHR_materials_transmission", "KHR_materials_ior"});
    if (glm::any(glm::greaterThan(kappa, glm::vec3(0.0f)))) {
        m.extensions["KHR_materials_volume"] = toValue(
            {{"thicknessFactor", 1.0},
             {"attenuationDistance", 1.0},
             {"attenuationColor", {std::exp(-kappa.x), std::exp(-kappa.y), std::exp(-kappa.z)}}});
        used.push_back("KHR_materials_volume");
    }
    model.materials.push_back(m);
    return static_cast<int>(model.materials.size()) - 1;
}

void checkExportable(const BakeData& d) {
    const SurfaceLayout& L = d.layout;
    if (L.isChartLayout())
        throw InputError(std::string("a ") + nameOf(L.kind) +
                         " (chart) layout: the glTF export draws the joining layout's sample grid; "
                         "bake with --layout joining");
    if (size_t(L.sampleCount()) > (size_t(1) << 24))
        throw InputError(std::to_string(L.sampleCount()) +
                         " samples: more than a float32 sample number (_SHREFRACT_SAMPLE) holds");
}

// The sample grid's triangles `all` (refinedTriangles) over the samples `part` selects (all: -1)
// as a primitive: each
// vertex a sample, named in _SHREFRACT_SAMPLE, its position and normal taken from the bake's space
// to the primitive's by `localFromBake` (normals by its inverse transpose).
tinygltf::Primitive samplePrimitive(BinaryBuffer& bin, const SurfaceLayout& L,
                                    const std::vector<uint32_t>& all, int part,
                                    const glm::dmat4& localFromBake) {
    const size_t N = static_cast<size_t>(L.sampleCount());
    std::vector<uint32_t> vertexOf(N, UINT32_MAX);
    std::vector<float> pos, nrm, sample;
    std::vector<double> lo(3, INFINITY), hi(3, -INFINITY);
    const glm::dmat3 normalFromBake = glm::transpose(glm::inverse(glm::dmat3(localFromBake)));
    const bool identity = localFromBake == glm::dmat4(1.0);
    for (size_t i = 0; i < N; ++i) {
        if (part >= 0 && L.part[i] != uint32_t(part)) continue;
        vertexOf[i] = static_cast<uint32_t>(sample.size());
        sample.push_back(static_cast<float>(i));
        // An identity keeps the bake's floats exactly.
        const glm::vec3 p = identity ? L.position[i] : glm::vec3(localFromBake * glm::dvec4(L.position[i], 1.0));
        const glm::vec3 n = identity ? L.normal[i] : glm::vec3(glm::normalize(normalFromBake * glm::dvec3(L.normal[i])));
        for (int c = 0; c < 3; ++c) {
            pos.push_back(p[c]);
            nrm.push_back(n[c]);
            lo[c] = std::min(lo[c], double(p[c]));
            hi[c] = std::max(hi[c], double(p[c]));
        }
    }
    // A mirroring transform turns the winding over: turn it back.
    const bool mirrored = glm::determinant(glm::dmat3(localFromBake)) < 0.0;
    std::vector<uint32_t> indices;
    for (size_t t = 0; t < all.size(); t += 3) {
        if (vertexOf[all[t]] == UINT32_MAX) continue;  // another part's
        indices.insert(indices.end(), {vertexOf[all[t]], vertexOf[all[t + (mirrored ? 2 : 1)]],
                                       vertexOf[all[t + (mirrored ? 1 : 2)]]});
    }
    const size_t V = sample.size();
    tinygltf::Primitive prim;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    prim.attributes["POSITION"] =
        bin.accessor(bin.view(pos.data(), pos.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                     TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, V, lo, hi);
    prim.attributes["NORMAL"] =
        bin.accessor(bin.view(nrm.data(), nrm.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                     TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, V);
    prim.attributes["_SHREFRACT_SAMPLE"] =
        bin.accessor(bin.view(sample.data(), sample.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                     TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, V);
    prim.indices =
        bin.accessor(bin.view(indices.data(), indices.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, indices.size());
    nlohmann::json ext = {{"refraction", 0}};
    if (!identity) {
        const glm::dmat4 bakeFromLocal = glm::inverse(localFromBake);
        std::vector<double> m;
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) m.push_back(bakeFromLocal[c][r]);
        ext["bakeFromLocal"] = m;
    }
    prim.extensions[kExtension] = toValue(ext);
    return prim;
}

// The refraction's data: atlas pages as PNG images, scale and offset, the error model, the front
// medium; its entry in the root extension.
nlohmann::json addRefraction(tinygltf::Model& model, BinaryBuffer& bin, const BakeData& d,
                             const std::string& name, int maxTexture) {
    const SurfaceLayout& L = d.layout;
    checkExportable(d);
    const size_t N = static_cast<size_t>(L.sampleCount());
    const float ior = frontIor(d);
    const glm::vec3 kappa = frontAbsorption(d);

    // The weights: one PNG image and texture per atlas page, nearest filtering, no mipmaps.
    const WeightAtlas atlas = weightAtlas(d, maxTexture);
    tinygltf::Sampler sampler;
    sampler.minFilter = TINYGLTF_TEXTURE_FILTER_NEAREST;
    sampler.magFilter = TINYGLTF_TEXTURE_FILTER_NEAREST;
    sampler.wrapS = sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    model.samplers.push_back(sampler);
    nlohmann::json pages = nlohmann::json::array();
    for (int p = 0; p < atlas.layout.pages; ++p) {
        const std::vector<uint8_t> png =
            encodePngRgba8(atlas.layout.pageWidth(p), atlas.layout.pageHeight(p), atlas.pages[p].data());
        tinygltf::Image image;
        image.name = name + "_weights_" + std::to_string(p);
        image.mimeType = "image/png";
        image.bufferView = bin.view(png.data(), png.size());
        model.images.push_back(image);
        tinygltf::Texture texture;
        texture.source = static_cast<int>(model.images.size()) - 1;
        texture.sampler = static_cast<int>(model.samplers.size()) - 1;
        model.textures.push_back(texture);
        pages.push_back(static_cast<int>(model.textures.size()) - 1);
    }
    const AtlasLayout& a = atlas.layout;
    nlohmann::json r = {
        {"name", name},
        {"basis", nameOf(d.basis)},
        {"order", d.order},
        {"coefficientCount", a.coefficients},
        {"sampleCount", N},
        {"tileSize", {a.tile[0], a.tile[1]}},
        {"tilesPerRow", a.tilesPerRow},
        {"tilesPerPage", a.tilesPerPage},
        {"weights", pages},
        {"scale", atlas.scale},
        {"offset", atlas.offset},
        {"ior", ior},
        {"absorption", {kappa.x, kappa.y, kappa.z}},
        {"boundsDiagonal", samplesDiagonal(L)},  // as the runtime's Refractor
    };
    if (d.basis == Basis::Grid) r["grid"] = {d.grid.nTheta, d.grid.nPhi};
    if (d.manifest.contains("branch") && d.manifest["branch"].is_string())
        r["branch"] = d.manifest["branch"];
    if (d.errorOrder >= 0) {
        r["error"] = {{"order", d.errorOrder},
                      {"coefficientCount", d.errorCoefficientCount()},
                      {"offset", kErrorOffset},
                      {"bufferView", bin.view(d.errors.data(), d.errors.size() * sizeof(float))}};
    }
    return r;
}

// A prefiltered cube map as the runtime uploads it, RGBA half floats, level by level.
nlohmann::json addEnvironment(BinaryBuffer& bin, const GltfEnvironment& e) {
    const PrefilteredCube cube = prefilterCube(e.base);
    std::vector<uint16_t> halves;
    for (const CubeMapImage& level : cube.levels)
        for (int f = 0; f < 6; ++f) {
            const std::vector<float>& rgb = level.faces[f];
            for (size_t t = 0; t < rgb.size() / 3; ++t) {
                for (int c = 0; c < 3; ++c) halves.push_back(glm::packHalf1x16(rgb[t * 3 + c]));
                halves.push_back(glm::packHalf1x16(1.0f));
            }
        }
    return {{"name", e.name},
            {"faceSize", e.base.faceSize},
            {"levels", cube.levels.size()},
            {"bufferView", bin.view(halves.data(), halves.size() * sizeof(uint16_t))}};
}

}  // namespace

int AtlasLayout::pageWidth(int p) const {
    const int onPage = std::min(tilesPerPage, coefficients - p * tilesPerPage);
    return std::min(onPage, tilesPerRow) * tile[0];
}

int AtlasLayout::pageHeight(int p) const {
    const int onPage = std::min(tilesPerPage, coefficients - p * tilesPerPage);
    return (onPage + tilesPerRow - 1) / tilesPerRow * tile[1];
}

AtlasLayout atlasLayout(int K, int N, int W, int maxSide) {
    if (K < 1 || N < 1 || W < 1) throw std::invalid_argument("atlasLayout: empty");
    AtlasLayout a;
    a.coefficients = K;
    a.tile[0] = W;
    a.tile[1] = (N + W - 1) / W;
    if (a.tile[0] > maxSide || a.tile[1] > maxSide)
        throw InputError("one coefficient's " + std::to_string(a.tile[0]) + " x " +
                         std::to_string(a.tile[1]) + " texels exceed the " +
                         std::to_string(maxSide) + " texel limit of a glTF texture here");
    // n tiles on a near-square page (as wide as tall), within the page limit.
    const int maxColumns = maxSide / a.tile[0], maxRows = maxSide / a.tile[1];
    const auto arrange = [&](int n) {
        a.tilesPerRow = std::clamp(static_cast<int>(std::ceil(std::sqrt(double(n) * a.tile[1] / a.tile[0]))), 1,
                                   maxColumns);
        const int rows = std::clamp((n + a.tilesPerRow - 1) / a.tilesPerRow, 1, maxRows);
        a.tilesPerRow = std::min(maxColumns, (n + rows - 1) / rows);  // rows at the limit: widen
        a.tilesPerPage = a.tilesPerRow * rows;
        a.pages = (K + a.tilesPerPage - 1) / a.tilesPerPage;
    };
    // As few pages as the limit allows, then the coefficients shared out evenly among them: a
    // last page holding a few tiles would cost a whole layer in the web material's array texture,
    // whose layers all have the largest page's size (512 grid tiles at 4096: 441 + 71 tiles made
    // two 4095 x 4074 layers, 256 + 256 make two of 3120 x 3104).
    arrange(K);
    if (a.pages > 1) arrange((K + a.pages - 1) / a.pages);
    return a;
}

WeightAtlas weightAtlas(const BakeData& d, int maxSide) {
    const int K = d.coefficientCount();
    const int N = d.layout.sampleCount();
    WeightAtlas out;
    out.layout = atlasLayout(K, N, d.layout.muWidth, maxSide);
    const AtlasLayout& a = out.layout;
    out.scale.resize(size_t(K) * 4);
    out.offset.resize(size_t(K) * 4);
    const nlohmann::json& m = d.manifest;
    if (d.precision == Precision::U8 && m.contains("u8") && m["u8"].is_object()) {
        // The bake's own codes: its scale and offset in double precision, as the file reader
        // dequantized them (docs/format.md "8-bit weights"), so that rounding back gives each code.
        out.scale = m["u8"]["scale"].get<std::vector<double>>();
        out.offset = m["u8"]["offset"].get<std::vector<double>>();
        out.scale.resize(size_t(K) * 4), out.offset.resize(size_t(K) * 4);
    } else {
        const format_internal::U8Params q = format_internal::fitU8(d);
        out.scale = q.scale, out.offset = q.offset;
    }
    for (int p = 0; p < a.pages; ++p)
        out.pages.emplace_back(size_t(a.pageWidth(p)) * a.pageHeight(p) * 4, uint8_t(0));
    for (int k = 0; k < K; ++k) {
        const int p = k / a.tilesPerPage, j = k % a.tilesPerPage;
        const int x0 = (j % a.tilesPerRow) * a.tile[0], y0 = (j / a.tilesPerRow) * a.tile[1];
        const int width = a.pageWidth(p);
        std::vector<uint8_t>& page = out.pages[p];
        for (int i = 0; i < N; ++i) {
            const size_t texel = size_t(y0 + i / a.tile[0]) * width + (x0 + i % a.tile[0]);
            for (int c = 0; c < 4; ++c) {
                const double scale = out.scale[k * 4 + c], offset = out.offset[k * 4 + c];
                const float w = d.weights[(size_t(k) * N + i) * 4 + c];
                page[texel * 4 + c] = static_cast<uint8_t>(format_internal::quantU8(w, scale, offset));
            }
        }
    }
    return out;
}

std::vector<uint8_t> exportGlb(const GltfExport& what) {
    if (!what.bake && what.environments.empty())
        throw std::invalid_argument("exportGlb: neither a bake nor an environment to export");
    tinygltf::Model model;
    model.asset.version = "2.0";
    model.asset.generator = "shrefract-export";
    BinaryBuffer bin(model);
    std::vector<std::string> used = {kExtension};
    nlohmann::json root = {{"version", kExtensionVersion}};
    if (what.bake) {
        root["refractions"] = {addRefraction(model, bin, *what.bake, what.name, what.maxTexture)};
        // One node, one mesh: the whole sample grid, vertex v sample v, with a plain glass material.
        tinygltf::Primitive prim = samplePrimitive(bin, what.bake->layout, refinedTriangles(what.bake->layout), -1, glm::dmat4(1.0));
        prim.material = glassMaterial(model, frontIor(*what.bake), frontAbsorption(*what.bake), used);
        tinygltf::Mesh mesh;
        mesh.name = what.name;
        mesh.primitives.push_back(prim);
        model.meshes.push_back(mesh);
        tinygltf::Node node;
        node.name = what.name;
        node.mesh = 0;
        model.nodes.push_back(node);
        tinygltf::Scene scene;
        scene.name = what.name;
        scene.nodes.push_back(0);
        model.scenes.push_back(scene);
        model.defaultScene = 0;
    }
    if (!what.environments.empty()) {
        root["environments"] = nlohmann::json::array();
        for (const GltfEnvironment& e : what.environments) root["environments"].push_back(addEnvironment(bin, e));
    }
    model.extensions[kExtension] = toValue(root);
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    model.extensionsUsed = used;
    return glbBytes(model);
}

namespace {

std::string sniffMime(const std::vector<unsigned char>& b, const std::string& uri) {
    if (b.size() >= 8 && b[0] == 0x89 && b[1] == 'P' && b[2] == 'N' && b[3] == 'G') return "image/png";
    if (b.size() >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF) return "image/jpeg";
    if (b.size() >= 12 && std::memcmp(b.data(), "RIFF", 4) == 0 && std::memcmp(b.data() + 8, "WEBP", 4) == 0)
        return "image/webp";
    throw InputError("image '" + uri + "' is neither PNG, JPEG nor WebP");
}

// Everything in one GLB: every buffer appended to buffer 0 (views re-pointed), and every image
// that lives in a file or a data URI moved into a view of it, bytes unchanged.
void gatherIntoOneBuffer(tinygltf::Model& model) {
    std::vector<unsigned char> all;
    std::vector<size_t> base;
    for (const tinygltf::Buffer& b : model.buffers) {
        all.resize((all.size() + 3) / 4 * 4, 0);
        base.push_back(all.size());
        all.insert(all.end(), b.data.begin(), b.data.end());
    }
    for (tinygltf::BufferView& v : model.bufferViews) {
        v.byteOffset += base.at(size_t(v.buffer));
        v.buffer = 0;
    }
    model.buffers.assign(1, tinygltf::Buffer());
    model.buffers[0].data = std::move(all);
    BinaryBuffer bin(model, false);
    for (tinygltf::Image& image : model.images) {
        if (image.bufferView < 0) {
            image.mimeType = sniffMime(image.image, image.uri);
            image.bufferView = bin.view(image.image.data(), image.image.size());
            image.uri.clear();
        }
        image.image.clear();
    }
}

}  // namespace

std::vector<uint8_t> exportInto(const BakeData& bake, const std::string& scenePath,
                                const std::vector<GltfEnvironment>& environments, int maxTexture) {
    checkExportable(bake);
    // The parts as the bake read them, and where each came from.
    tinygltf::Model model;
    readGltfModel(scenePath, model, true);
    std::vector<GltfPlace> places;
    const Scene scene = gltfSceneOf(scenePath, model, &places);
    const nlohmann::json& media = bake.manifest.contains("media") ? bake.manifest["media"] : nlohmann::json();
    if (!media.is_array() || media.size() != scene.parts.size())
        throw InputError("the bake has " + std::to_string(media.is_array() ? media.size() : 0) +
                         " parts and " + scenePath + " " + std::to_string(scene.parts.size()) +
                         " glass parts: it was not baked from this file");
    for (size_t p = 0; p < scene.parts.size(); ++p)
        if (media[p].value("meshChecksum", std::string()) != scene.parts[p].mesh.checksum())
            throw InputError("glass part '" + scene.parts[p].name + "' of " + scenePath +
                             " is not the mesh the bake traced (its checksum differs): re-bake it");

    gatherIntoOneBuffer(model);
    BinaryBuffer bin(model, false);

    nlohmann::json root = {{"version", kExtensionVersion}};
    const std::string name = std::filesystem::path(scenePath).stem().string();
    root["refractions"] = {addRefraction(model, bin, bake, name, maxTexture)};
    // Each glass primitive becomes the sample grid of its part, in its node's coordinates, with
    // its own material. A mesh several glass nodes share is copied for each but the first.
    std::vector<int> meshUsers(model.meshes.size(), 0);
    for (size_t p = 0; p < places.size(); ++p) {
        const GltfPlace& at = places[p];
        tinygltf::Node& node = model.nodes.at(size_t(at.node));
        if (node.mesh != at.mesh) continue;  // already given its own copy
        bool shared = false;
        for (size_t n = 0; n < model.nodes.size(); ++n)
            shared |= n != size_t(at.node) && model.nodes[n].mesh == at.mesh;
        if (shared && meshUsers[size_t(at.mesh)]++ > 0) {
            model.meshes.push_back(model.meshes[size_t(at.mesh)]);
            node.mesh = static_cast<int>(model.meshes.size()) - 1;
        }
    }
    const std::vector<uint32_t> triangles = refinedTriangles(bake.layout);
    for (size_t p = 0; p < places.size(); ++p) {
        const GltfPlace& at = places[p];
        const int meshIndex = model.nodes.at(size_t(at.node)).mesh;
        tinygltf::Primitive& old = model.meshes.at(size_t(meshIndex)).primitives.at(size_t(at.primitive));
        tinygltf::Primitive prim = samplePrimitive(bin, bake.layout, triangles, int(p), glm::inverse(at.world));
        prim.material = old.material;
        old = prim;
    }
    if (!environments.empty()) {
        root["environments"] = nlohmann::json::array();
        for (const GltfEnvironment& e : environments) root["environments"].push_back(addEnvironment(bin, e));
    }
    model.extensions[kExtension] = toValue(root);
    if (std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), kExtension) ==
        model.extensionsUsed.end())
        model.extensionsUsed.push_back(kExtension);
    return glbBytes(model);
}

namespace {

std::vector<uint8_t> glbBytes(tinygltf::Model& model) {
    model.buffers[0].data.resize((model.buffers[0].data.size() + 3) / 4 * 4, 0);
    std::ostringstream stream;
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&model, stream, false, true))
        throw IoError("tinygltf could not write the GLB");
    const std::string s = stream.str();
    return std::vector<uint8_t>(s.begin(), s.end());
}

}  // namespace

}  // namespace shrefract
