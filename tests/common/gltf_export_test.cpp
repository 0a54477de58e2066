// The glTF export (common/gltf/gltf_export.h, docs/format.md "glTF export"), read back through
// tinygltf's own parser and its stb PNG decoder: an independent reader of what the writer wrote.
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>
#include <set>

#include "common/error.h"
#include "common/gltf/gltf_export.h"
#include "common/prefilter.h"
#include "common/sh.h"
#include "support/cli_run.h"
#include "support/files.h"
#include "support/synthetic_bake.h"

namespace shrefract {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

tinygltf::Model parse(const std::vector<uint8_t>& glb) {
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    const bool ok = loader.LoadBinaryFromMemory(&model, &err, &warn, glb.data(),
                                                static_cast<unsigned>(glb.size()));
    EXPECT_TRUE(ok) << err;
    EXPECT_TRUE(err.empty()) << err;
    return model;
}

// tinygltf's Value back as JSON, through its own serialization of the model's extension.
json rootExtension(const tinygltf::Model& m) {
    const tinygltf::Value& v = m.extensions.at("SHREFRACT_sh_refraction");
    std::function<json(const tinygltf::Value&)> conv = [&](const tinygltf::Value& x) -> json {
        if (x.IsObject()) {
            json o = json::object();
            for (const std::string& k : x.Keys()) o[k] = conv(x.Get(k));
            return o;
        }
        if (x.IsArray()) {
            json a = json::array();
            for (size_t i = 0; i < x.ArrayLen(); ++i) a.push_back(conv(x.Get(int(i))));
            return a;
        }
        if (x.IsBool()) return x.Get<bool>();
        if (x.IsInt()) return x.Get<int>();
        if (x.IsNumber()) return x.GetNumberAsDouble();
        if (x.IsString()) return x.Get<std::string>();
        return nullptr;
    };
    return conv(v);
}

const unsigned char* viewBytes(const tinygltf::Model& m, int view, size_t* length) {
    const tinygltf::BufferView& v = m.bufferViews.at(size_t(view));
    *length = v.byteLength;
    return m.buffers.at(size_t(v.buffer)).data.data() + v.byteOffset;
}

// IEEE binary16 by its definition (sign, 5 exponent bits biased by 15, 10 fraction bits), not
// through glm, which wrote them.
float halfToFloat(uint16_t h) {
    const int e = (h >> 10) & 31, f = h & 1023;
    const float v = e == 0 ? std::ldexp(float(f), -24) : std::ldexp(1.0f + f / 1024.0f, e - 15);
    return (h & 0x8000) ? -v : v;
}

// Weight k, channel c of sample i as the spec says to decode it, from the decoded atlas pages.
float decoded(const tinygltf::Model& m, const json& r, int k, int i, int c) {
    const int W = r["tileSize"][0], H = r["tileSize"][1];
    const int perRow = r["tilesPerRow"], perPage = r["tilesPerPage"];
    const int page = k / perPage, j = k % perPage;
    const tinygltf::Image& img = m.images.at(size_t(m.textures.at(r["weights"][page].get<size_t>()).source));
    const int x = (j % perRow) * W + i % W, y = (j / perRow) * H + i / W;
    const int code = img.image.at((size_t(y) * img.width + x) * 4 + c);
    return static_cast<float>(r["scale"][4 * k + c].get<double>() * code + r["offset"][4 * k + c].get<double>());
}

TEST(GltfExport, WeightsDecodeToTheBakesWithinHalfACode) {
    BakeData d = test::syntheticBake(Precision::F32);
    d.errorOrder = 2;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-5.0f, 0.0f);
    d.errors.resize(size_t(d.errorCoefficientCount()) * d.layout.sampleCount());
    for (float& e : d.errors) e = u(rng);
    GltfExport what;
    what.bake = &d;
    what.name = "synthetic";
    const tinygltf::Model m = parse(exportGlb(what));
    const json root = rootExtension(m);
    ASSERT_EQ(root["version"], 2);
    const json& r = root["refractions"][0];
    EXPECT_EQ(r["basis"], "sh");
    EXPECT_FALSE(r.contains("grid"));
    const int K = d.coefficientCount(), N = d.layout.sampleCount();
    ASSERT_EQ(r["coefficientCount"], K);
    ASSERT_EQ(r["sampleCount"], N);
    ASSERT_EQ(r["order"], 4);
    EXPECT_EQ(r["tileSize"][0], d.layout.muWidth);
    EXPECT_NEAR(r["ior"].get<double>(), 1.5, 1e-7);  // the first medium's
    // Every channel within half a code step of the float weight (plus float rounding).
    double worst = 0;
    for (int k = 0; k < K; ++k)
        for (int i = 0; i < N; ++i)
            for (int c = 0; c < 4; ++c) {
                const double step = r["scale"][4 * k + c].get<double>();
                const double err = std::abs(decoded(m, r, k, i, c) - d.weights[(size_t(k) * N + i) * 4 + c]);
                worst = std::max(worst, err / step);
            }
    EXPECT_LE(worst, 0.5 + 1e-4);
    EXPECT_GT(worst, 0.3);  // the codes are rounded, not exact: random weights land between codes
    // The error model verbatim.
    size_t bytes = 0;
    const unsigned char* e = viewBytes(m, r["error"]["bufferView"], &bytes);
    ASSERT_EQ(bytes, d.errors.size() * 4);
    EXPECT_EQ(std::memcmp(e, d.errors.data(), bytes), 0);
    EXPECT_EQ(r["error"]["coefficientCount"], 6);
}

TEST(GltfExport, GridBakesCarryTheirTracedExits) {
    // The synthetic bake's samples with a 3 x 6 grid of exits (its 15 random coefficients, three
    // more at 0.25): the refraction names the basis and the grid, and every exit decodes.
    BakeData d = test::syntheticBake(Precision::F32);
    d.basis = Basis::Grid;
    d.order = 0;
    d.grid = DirectionGrid{3, 6};
    d.weights.resize(size_t(d.grid.count()) * d.layout.sampleCount() * 4, 0.25f);
    GltfExport what;
    what.bake = &d;
    const tinygltf::Model m = parse(exportGlb(what));
    const json root = rootExtension(m);
    ASSERT_EQ(root["version"], 2);
    const json& r = root["refractions"][0];
    EXPECT_EQ(r["basis"], "grid");
    EXPECT_EQ(r["grid"], json::array({3, 6}));
    EXPECT_EQ(r["order"], 0);
    const int K = 18, N = d.layout.sampleCount();
    ASSERT_EQ(r["coefficientCount"], K);
    ASSERT_EQ(r["scale"].size(), size_t(4 * K));
    double worst = 0;
    for (int k = 0; k < K; ++k)
        for (int i = 0; i < N; ++i)
            for (int c = 0; c < 4; ++c) {
                const double step = std::max(r["scale"][4 * k + c].get<double>(), 1e-12);
                worst = std::max(worst, std::abs(decoded(m, r, k, i, c) - d.weights[(size_t(k) * N + i) * 4 + c]) / step);
            }
    EXPECT_LE(worst, 0.5 + 1e-4);  // the last three coefficients (constant 0.25) included
}

TEST(GltfExport, U8BakesKeepTheirCodesExactly) {
    // A u8 bake through the file format (its weights dequantized from codes), then exported: every
    // decoded value is the bake's value, bit for bit, as the C++ runtime's u8 upload reads it.
    const fs::path dir = test::scratchFolder("gltf_u8");
    writeBake((dir / "u8.shrefract.exr").string(), test::syntheticBake(Precision::U8));
    const BakeData d = readBake((dir / "u8.shrefract.exr").string());
    GltfExport what;
    what.bake = &d;
    const tinygltf::Model m = parse(exportGlb(what));
    const json r = rootExtension(m)["refractions"][0];
    const int K = d.coefficientCount(), N = d.layout.sampleCount();
    int mismatches = 0;
    for (int k = 0; k < K; ++k)
        for (int i = 0; i < N; ++i)
            for (int c = 0; c < 4; ++c)
                mismatches += decoded(m, r, k, i, c) != d.weights[(size_t(k) * N + i) * 4 + c];
    EXPECT_EQ(mismatches, 0);
}

// maxTexture at one tile's side (shrefract-export --max-texture): more, smaller pages, and every
// decoded value what the default export's single page holds.
TEST(GltfExport, SmallerPagesHoldTheSameWeights) {
    const BakeData d = test::syntheticBake(Precision::F32);
    GltfExport what;
    what.bake = &d;
    const tinygltf::Model one = parse(exportGlb(what));
    const json r1 = rootExtension(one)["refractions"][0];
    ASSERT_EQ(r1["weights"].size(), 1u);
    what.maxTexture = std::max(r1["tileSize"][0].get<int>(), r1["tileSize"][1].get<int>());
    const tinygltf::Model many = parse(exportGlb(what));
    const json r = rootExtension(many)["refractions"][0];
    EXPECT_GT(r["weights"].size(), 1u);
    for (const auto& t : r["weights"]) {
        const tinygltf::Image& img = many.images.at(size_t(many.textures.at(t.get<size_t>()).source));
        EXPECT_LE(std::max(img.width, img.height), what.maxTexture);
    }
    const int K = d.coefficientCount(), N = d.layout.sampleCount();
    int mismatches = 0;
    for (int k = 0; k < K; ++k)
        for (int i = 0; i < N; ++i)
            for (int c = 0; c < 4; ++c) mismatches += decoded(many, r, k, i, c) != decoded(one, r1, k, i, c);
    EXPECT_EQ(mismatches, 0);
    // Below one tile it is refused.
    what.maxTexture -= 1;
    EXPECT_THROW(exportGlb(what), InputError);
}

TEST(GltfExport, TheMeshIsTheSampleGrid) {
    const BakeData d = test::syntheticBake(Precision::F32);
    GltfExport what;
    what.bake = &d;
    const tinygltf::Model m = parse(exportGlb(what));
    ASSERT_EQ(m.meshes.size(), 1u);
    const tinygltf::Primitive& p = m.meshes[0].primitives.at(0);
    EXPECT_EQ(p.mode, TINYGLTF_MODE_TRIANGLES);
    ASSERT_TRUE(p.extensions.count("SHREFRACT_sh_refraction"));
    const tinygltf::Accessor& pos = m.accessors.at(size_t(p.attributes.at("POSITION")));
    ASSERT_EQ(pos.count, d.layout.position.size());
    size_t bytes = 0;
    const auto* xyz = reinterpret_cast<const float*>(viewBytes(m, pos.bufferView, &bytes));
    for (size_t i = 0; i < pos.count; ++i)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(xyz[i * 3 + c], d.layout.position[i][c]) << i;
    const tinygltf::Accessor& ids0 = m.accessors.at(size_t(p.attributes.at("_SHREFRACT_SAMPLE")));
    const auto* sampleOf = reinterpret_cast<const float*>(viewBytes(m, ids0.bufferView, &bytes));
    for (size_t i = 0; i < ids0.count; ++i) ASSERT_EQ(sampleOf[i], float(i));
    // Indices: r^2 small triangles per triangle, and the corners of every baked triangle (its grid
    // samples (0,0), (r,0), (0,r)) are vertices of the mesh at those sample numbers.
    const tinygltf::Accessor& idx = m.accessors.at(size_t(p.indices));
    const int r = d.layout.rate;
    EXPECT_EQ(idx.count, size_t(d.layout.triangleCount) * r * r * 3);
    const auto* ids = reinterpret_cast<const uint32_t*>(viewBytes(m, idx.bufferView, &bytes));
    std::set<uint32_t> used(ids, ids + idx.count);
    for (int t = 0; t < d.layout.triangleCount; ++t)
        for (auto [i, j] : {std::pair{0, 0}, {r, 0}, {0, r}}) EXPECT_TRUE(used.count(d.layout.sampleAt(t, i, j)));
    EXPECT_LT(*used.rbegin(), pos.count);
    // A plain glass material for viewers that do not know the extension.
    const tinygltf::Material& mat = m.materials.at(size_t(p.material));
    EXPECT_TRUE(mat.extensions.count("KHR_materials_transmission"));
    EXPECT_NEAR(mat.extensions.at("KHR_materials_ior").Get("ior").GetNumberAsDouble(), 1.5, 1e-7);
}

TEST(GltfExport, AtlasPagesStayWithinTheTextureLimit) {
    // 15 tiles of 7 x 6 on pages of at most 16 texels: 2 x 2 tiles a page, 4 pages.
    const BakeData d = test::syntheticBake(Precision::F32);
    const WeightAtlas a = weightAtlas(d, 16);
    EXPECT_EQ(a.layout.tilesPerPage, 4);
    EXPECT_EQ(a.layout.pages, 4);
    for (int p = 0; p < a.layout.pages; ++p) {
        EXPECT_LE(a.layout.pageWidth(p), 16);
        EXPECT_LE(a.layout.pageHeight(p), 16);
    }
    // The last page holds 3 tiles: two rows.
    EXPECT_EQ(a.layout.pageHeight(3), 12);
    // Coefficient 13 is page 3, tile 1: texel (7, 0) + sample 9's (2, 1); its code decodes.
    const int k = 13, i = 9, c = 3, N = d.layout.sampleCount();
    const uint8_t code = a.pages[3][(size_t(1) * a.layout.pageWidth(3) + 7 + 2) * 4 + c];
    EXPECT_NEAR(a.scale[4 * k + c] * code + a.offset[4 * k + c], d.weights[(size_t(k) * N + i) * 4 + c],
                a.scale[4 * k + c] / 2 + 1e-6);
    EXPECT_THROW(weightAtlas(d, 6), InputError);  // a 7-texel tile on a 6-texel page
}

TEST(GltfExport, PagesShareTheCoefficientsEvenly) {
    // The grid bunny's atlas (512 tiles of 195 x 194 at 4096 texels): 21 x 21 tiles fit a page,
    // so two pages. Shared evenly, 256 tiles each, near-square: 16 x 16 tiles, 3120 x 3104.
    const AtlasLayout g = atlasLayout(512, 37706, 195);
    EXPECT_EQ(g.pages, 2);
    EXPECT_EQ(g.tilesPerRow, 16);
    EXPECT_EQ(g.tilesPerPage, 256);
    for (int p = 0; p < 2; ++p) {
        EXPECT_EQ(g.pageWidth(p), 3120);
        EXPECT_EQ(g.pageHeight(p), 3104);
    }
    // Every count of tiles, three tile shapes, three limits: the fewest pages the limit allows,
    // each tile inside its page, and no page much emptier than the largest (a web material's array
    // texture gives every page the largest one's size).
    double worst = 1.0;
    for (const auto [w, h] : {std::pair{7, 6}, {195, 194}, {64, 3}})
        for (const int side : {16, 300, 4096}) {
            if (w > side || h > side) continue;
            const int perPageMax = (side / w) * (side / h);
            for (int K = 1; K <= 700; ++K) {
                const AtlasLayout a = atlasLayout(K, w * h, w, side);
                SCOPED_TRACE(testing::Message() << K << " tiles of " << w << " x " << h << " at " << side);
                ASSERT_EQ(a.pages, (K + perPageMax - 1) / perPageMax);
                ASSERT_GE(a.pages * a.tilesPerPage, K);
                int largest = 0;
                for (int p = 0; p < a.pages; ++p) {
                    ASSERT_LE(a.pageWidth(p), side);
                    ASSERT_LE(a.pageHeight(p), side);
                    largest = std::max(largest, a.pageWidth(p) * a.pageHeight(p));
                }
                for (int k = 0; k < K; ++k) {
                    const int p = k / a.tilesPerPage, j = k % a.tilesPerPage;
                    ASSERT_LE((j % a.tilesPerRow + 1) * w, a.pageWidth(p));
                    ASSERT_LE((j / a.tilesPerRow + 1) * h, a.pageHeight(p));
                }
                const double used = double(K) * w * h / (double(a.pages) * largest);
                if (a.pages > 1) worst = std::min(worst, used);
            }
        }
    // Measured: at worst 0.625 of the array's texels hold tiles (5 tiles on 2 x 2-tile pages: a
    // page of 4 and one of 1 cannot do better). Filling pages in turn, the last page holding what
    // is left, goes down to 0.501 (441 tiles and 1).
    EXPECT_GE(worst, 0.6);
}

TEST(GltfExport, AConstantEnvironmentStaysConstantAtEveryLevel) {
    GltfEnvironment e;
    e.name = "grey";
    e.base.faceSize = 8;
    for (auto& f : e.base.faces) f.assign(8 * 8 * 3, 0.0f);
    for (auto& f : e.base.faces)
        for (size_t t = 0; t < f.size(); t += 3) f[t] = 0.25f, f[t + 1] = 0.5f, f[t + 2] = 2.0f;
    GltfExport what;
    what.environments.push_back(e);
    const tinygltf::Model m = parse(exportGlb(what));
    EXPECT_TRUE(m.meshes.empty());
    const json env = rootExtension(m)["environments"][0];
    ASSERT_EQ(env["levels"], 4);  // 8, 4, 2, 1
    size_t bytes = 0;
    const auto* h = reinterpret_cast<const uint16_t*>(viewBytes(m, env["bufferView"], &bytes));
    ASSERT_EQ(bytes, size_t(6) * (64 + 16 + 4 + 1) * 4 * 2);
    for (size_t t = 0; t < bytes / 8; ++t) {
        // Halves of 0.25, 0.5, 2 and 1 (IEEE binary16: sign, 5 exponent bits, 10 fraction bits).
        ASSERT_NEAR(halfToFloat(h[t * 4 + 0]), 0.25f, 2e-3) << t;
        ASSERT_NEAR(halfToFloat(h[t * 4 + 1]), 0.5f, 2e-3) << t;
        ASSERT_NEAR(halfToFloat(h[t * 4 + 2]), 2.0f, 4e-3) << t;
        ASSERT_EQ(h[t * 4 + 3], 0x3c00);
    }
}

TEST(GltfExport, ChartBakesAreRefusedWithTheReason) {
    const BakeData d = test::syntheticChartBake(Precision::F32);
    GltfExport what;
    what.bake = &d;
    try {
        exportGlb(what);
        FAIL() << "a chart bake was exported";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--layout joining"), std::string::npos) << e.what();
    }
}

TEST(GltfExport, TheToolRefusesBadInputAndLeavesTheOutputAlone) {
    const fs::path dir = test::scratchFolder("gltf_cli");
    const fs::path out = dir / "out.glb";
    test::writeFile(out, "precious");
    const std::string exe = SHREFRACT_EXPORT_EXE;
    const test::CommandResult missing = test::run(exe + " " + (dir / "nope.shrefract.exr").string() + " -o " + out.string());
    EXPECT_EQ(missing.code, 2);
    EXPECT_NE(missing.out.find("nope.shrefract.exr"), std::string::npos) << missing.out;
    test::writeFile(dir / "junk.shrefract.exr", "not an EXR at all");
    const test::CommandResult junk = test::run(exe + " " + (dir / "junk.shrefract.exr").string() + " -o " + out.string());
    EXPECT_EQ(junk.code, 2);
    EXPECT_NE(junk.out.find("junk.shrefract.exr"), std::string::npos) << junk.out;
    EXPECT_EQ(test::readFile(out), "precious");
}

}  // namespace
}  // namespace shrefract
