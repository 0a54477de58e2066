// Round trips and failure modes of NAME.shrefract.exr (common/bakefile.h, docs/format.md).
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfRgbaFile.h>
#include <ImfStringAttribute.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "common/bakefile.h"
#include "common/checksum.h"
#include "common/decompress.h"
#include "common/error.h"
#include "common/sh.h"
#include "support/files.h"
#include "support/synthetic_bake.h"

namespace shrefract {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A scratch folder per test, so that tests may run in parallel and "no temporary file is left"
// looks only at this test's files.
fs::path scratch() { return test::scratchFolder("format"); }

using test::syntheticBake;
using test::syntheticChartBake;

using test::readFile;
using test::writeFile;

// The temporary files of writes (writeAtomically) left in `dir`, sorted.
std::vector<std::string> leftovers(const fs::path& dir) {
    std::vector<std::string> names;
    for (const std::string& name : test::listing(dir))
        if (name.find(".shrefract-tmp.") != std::string::npos) names.push_back(name);
    return names;
}

void expectAtlasEqual(const ChartAtlas& a, const ChartAtlas& b) {
    EXPECT_EQ(a.gutter, b.gutter);
    EXPECT_EQ(a.chartCount, b.chartCount);
    EXPECT_EQ(a.vertexPosition, b.vertexPosition);
    EXPECT_EQ(a.vertexNormal, b.vertexNormal);
    EXPECT_EQ(a.vertexUV, b.vertexUV);
    EXPECT_EQ(a.vertexChart, b.vertexChart);
    EXPECT_EQ(a.triangles, b.triangles);
    EXPECT_EQ(a.sampleTexel, b.sampleTexel);
    ASSERT_EQ(a.seam.size(), b.seam.size());
    for (size_t e = 0; e < a.seam.size(); ++e) {
        EXPECT_EQ(a.seam[e].texel, b.seam[e].texel) << e;
        for (int k = 0; k < 4; ++k) {
            EXPECT_EQ(a.seam[e].sample[k], b.seam[e].sample[k]) << e;
            EXPECT_EQ(a.seam[e].weight[k], b.seam[e].weight[k]) << e;
        }
    }
}

void expectLayoutEqual(const SurfaceLayout& a, const SurfaceLayout& b) {
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(a.rate, b.rate);
    EXPECT_EQ(a.muWidth, b.muWidth);
    EXPECT_EQ(a.muHeight, b.muHeight);
    EXPECT_EQ(a.rhoWidth, b.rhoWidth);
    EXPECT_EQ(a.rhoHeight, b.rhoHeight);
    EXPECT_EQ(a.blockWidth, b.blockWidth);
    EXPECT_EQ(a.blockHeight, b.blockHeight);
    EXPECT_EQ(a.blocksPerRow, b.blocksPerRow);
    EXPECT_EQ(a.triangleCount, b.triangleCount);
    ASSERT_EQ(a.sampleCount(), b.sampleCount());
    for (int i = 0; i < a.sampleCount(); ++i) {
        EXPECT_EQ(a.position[i], b.position[i]) << "sample " << i;
        EXPECT_EQ(a.normal[i], b.normal[i]) << "sample " << i;
    }
    EXPECT_EQ(a.part, b.part);
    ASSERT_EQ(a.rho.size(), b.rho.size());
    for (size_t t = 0; t < a.rho.size(); ++t) {
        EXPECT_EQ(a.rho[t].kind, b.rho[t].kind) << "texel " << t;
        EXPECT_EQ(a.rho[t].a, b.rho[t].a) << "texel " << t;
        EXPECT_EQ(a.rho[t].b, b.rho[t].b) << "texel " << t;
        EXPECT_EQ(a.rho[t].c, b.rho[t].c) << "texel " << t;
    }
    EXPECT_EQ(a.neighbourOffset, b.neighbourOffset);
    EXPECT_EQ(a.neighbourCount, b.neighbourCount);
    EXPECT_EQ(a.neighbourIndex, b.neighbourIndex);
    EXPECT_EQ(a.neighbourWeight, b.neighbourWeight);
}

// The channels of each part in the order docs/format.md gives them, which is the order a part's
// checksum takes them in (texels row-major, each texel's channels in this order).
std::vector<std::string> documentedChannels(const std::string& part, const Imf::Header& h) {
    if (part == "samples") return {"P.x", "P.y", "P.z", "N.x", "N.y", "N.z", "part"};
    if (part == "rho") return {"kind", "a", "b", "c"};
    if (part == "neighbours") return {"offset", "count"};
    if (part == "neighbour_list") return {"index", "weight"};
    if (part == "chart_vertices") return {"P.x", "P.y", "P.z", "N.x", "N.y", "N.z", "u", "v", "chart"};
    if (part == "chart_triangles") return {"a", "b", "c"};
    if (part == "seam_sources") return {"texel", "s0", "s1", "s2", "s3", "w0", "w1", "w2", "w3"};
    std::vector<std::string> names;  // weights: w000.x, w000.y, w000.z, w000.len, w001.x, ...
    for (int k = 0;; ++k) {
        char base[16];
        std::snprintf(base, sizeof base, "w%03d.", k);
        if (h.channels().findChannel(std::string(base) + "rgba8")) {
            names.push_back(std::string(base) + "rgba8");
        } else if (h.channels().findChannel(std::string(base) + "x")) {
            for (const char* c : {"x", "y", "z", "len"}) names.push_back(std::string(base) + c);
        } else {
            return names;
        }
    }
}

// Copies a bake part by part, channel by channel, letting the test edit the manifest (of every
// part) and the raw pixels: a way to make files that writeBake would never write. With `resign`
// the copy gets the checksums of what it holds (the part checksums and the manifest's, computed
// here from docs/format.md), so that only the edited content can make it wrong; without, the
// old checksums stay: a corrupt file.
using PixelEdit = std::function<void(const std::string& part, const std::string& channel,
                                     std::vector<char>& bytes)>;
void rewrite(const fs::path& src, const fs::path& dst, const std::function<void(json&)>& edit,
             const PixelEdit& pixels = nullptr, bool resign = true) {
    Imf::MultiPartInputFile in(src.c_str());
    std::vector<Imf::Header> headers;
    std::vector<std::map<std::string, std::vector<char>>> planes(in.parts());
    json sums = json::object();
    for (int p = 0; p < in.parts(); ++p) {
        headers.push_back(in.header(p));
        const Imf::Header& h = headers.back();
        const Imath::Box2i dw = h.dataWindow();
        const int w = dw.max.x + 1, ht = dw.max.y + 1;
        Imf::FrameBuffer fb;
        for (auto c = h.channels().begin(); c != h.channels().end(); ++c) {
            const size_t size = c.channel().type == Imf::HALF ? 2 : 4;
            auto& bytes = planes[p][c.name()];
            bytes.resize(size * w * ht);
            fb.insert(c.name(), Imf::Slice(c.channel().type, bytes.data(), size, size * w));
        }
        Imf::InputPart ip(in, p);
        ip.setFrameBuffer(fb);
        ip.readPixels(0, ht - 1);
        if (pixels)
            for (auto& [name, bytes] : planes[p]) pixels(h.name(), name, bytes);
        // Interleave in the documented order for the checksum.
        const std::vector<std::string> order = documentedChannels(h.name(), h);
        std::string staged;
        for (size_t t = 0; t < size_t(w) * ht; ++t)
            for (const std::string& c : order) {
                const auto& bytes = planes[p].at(c);
                const size_t size = bytes.size() / (size_t(w) * ht);
                staged.append(&bytes[t * size], size);
            }
        sums[h.name()] = checksumHex(staged);
    }
    for (Imf::Header& h : headers) {
        auto& attr = h.typedAttribute<Imf::StringAttribute>("shrefract.manifest");
        json m = json::parse(attr.value());
        if (resign && m.contains("checksums")) m["checksums"]["parts"] = sums;
        edit(m);
        attr.value() = m.dump();
        if (resign && h.findTypedAttribute<Imf::StringAttribute>("shrefract.manifestChecksum"))
            h.typedAttribute<Imf::StringAttribute>("shrefract.manifestChecksum").value() =
                checksumHex(attr.value());
    }
    Imf::MultiPartOutputFile out(dst.c_str(), headers.data(), int(headers.size()));
    for (int p = 0; p < in.parts(); ++p) {
        const Imath::Box2i dw = headers[p].dataWindow();
        const int w = dw.max.x + 1, ht = dw.max.y + 1;
        Imf::FrameBuffer fb;
        for (auto c = headers[p].channels().begin(); c != headers[p].channels().end(); ++c) {
            auto& bytes = planes[p][c.name()];
            const size_t size = bytes.size() / (size_t(w) * ht);
            fb.insert(c.name(), Imf::Slice(c.channel().type, bytes.data(), size, size * w));
        }
        Imf::OutputPart op(out, p);
        op.setFrameBuffer(fb);
        op.writePixels(ht);
    }
}

// Expects readBake(path) to throw InputError whose message names the file and contains `what`.
void expectInputError(const fs::path& path, const std::string& what) {
    try {
        readBake(path.string());
        FAIL() << "readBake(" << path << ") did not throw";
    } catch (const InputError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find(path.string()), std::string::npos) << msg;
        EXPECT_NE(msg.find(what), std::string::npos) << msg;
    }
}

TEST(Format, PrecisionNamesRoundTrip) {
    for (Precision p : {Precision::F32, Precision::F16, Precision::U8})
        EXPECT_EQ(parseInput<Precision>(nameOf(p)), p) << nameOf(p);
    EXPECT_THROW(parseInput<Precision>("f64"), InputError);
    EXPECT_THROW(parseInput<Precision>("F32"), InputError);
}

TEST(Format, CoefficientCountIsEvenParityCount) {
    BakeData d;
    d.order = 8;
    EXPECT_EQ(d.coefficientCount(), 45);  // docs/conventions.md: 45 of 81 at L = 8
    d.order = 4;
    EXPECT_EQ(d.coefficientCount(), 15);
}

TEST(Format, RoundTripF32IsExact) {
    const fs::path path = scratch() / "f32.shrefract.exr";
    const BakeData d = syntheticBake(Precision::F32);
    writeBake(path.string(), d);
    const BakeData r = readBake(path.string());
    EXPECT_EQ(r.order, d.order);
    EXPECT_EQ(r.precision, Precision::F32);
    ASSERT_EQ(r.weights.size(), d.weights.size());
    for (size_t v = 0; v < d.weights.size(); ++v)
        ASSERT_EQ(r.weights[v], d.weights[v]) << "weight " << v;
    EXPECT_TRUE(r.u8Scale.empty());
    EXPECT_TRUE(r.u8Offset.empty());
    EXPECT_TRUE(leftovers(path.parent_path()).empty());
}

// Version 4's grid basis (docs/format.md "weights"): one coefficient per grid direction, the grid
// in the manifest, order 0; it reads back as written, and the CPU decompressor at a grid
// direction returns that direction's weights (a node of the bilinear interpolation).
TEST(Format, GridBasisRoundTrips) {
    const fs::path path = scratch() / "grid.shrefract.exr";
    BakeData d = syntheticBake(Precision::F32);
    d.basis = Basis::Grid;
    d.order = 0;
    d.grid = DirectionGrid{4, 8};
    const size_t n = d.layout.position.size();
    d.weights.resize(32 * n * 4);
    for (size_t v = 0; v < d.weights.size(); ++v) d.weights[v] = float(v % 1009) / 1009.0f;
    writeBake(path.string(), d);
    const BakeData r = readBake(path.string());
    EXPECT_EQ(r.basis, Basis::Grid);
    EXPECT_EQ(r.grid.ToString(), "4x8");
    EXPECT_EQ(r.coefficientCount(), 32);
    EXPECT_EQ(r.manifest.value("basis", ""), "grid");
    ASSERT_EQ(r.weights, d.weights);
    for (int j = 0; j < 32; ++j) {
        const glm::vec4 got = decompressSample(r, 5, glm::vec3(r.grid.direction(j)));
        const float* want = &d.weights[(size_t(j) * n + 5) * 4];
        for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], want[c], 1e-5f) << "direction " << j;
    }
    // An SH bake has no "basis" key, as every file before version 4.
    const fs::path sh = scratch() / "sh_basis.shrefract.exr";
    writeBake(sh.string(), syntheticBake(Precision::F32));
    EXPECT_FALSE(readBake(sh.string()).manifest.contains("basis"));
}

// Version 3's error model (docs/format.md "error"): stored as float, whatever the weights'
// precision, bit for bit; its manifest says what it holds.
TEST(Format, ErrorModelRoundTripsExactly) {
    for (Precision p : {Precision::F32, Precision::U8}) {
        const fs::path path = scratch() / (std::string(nameOf(p)) + ".shrefract.exr");
        BakeData d = syntheticBake(p);
        d.errorOrder = 2;
        std::mt19937 rng(3);
        std::uniform_real_distribution<float> u(-0.5f, 1.5f);
        d.errors.resize(size_t(shEvenCount(2)) * d.layout.sampleCount());
        for (float& e : d.errors) e = u(rng);
        writeBake(path.string(), d);
        const BakeData r = readBake(path.string());
        EXPECT_EQ(r.manifest["version"], kFormatVersion);
        EXPECT_EQ(r.manifest["errorModel"]["order"], 2);
        EXPECT_EQ(r.manifest["errorModel"]["unit"], "radians");
        ASSERT_EQ(r.errorOrder, 2);
        ASSERT_EQ(r.errors, d.errors) << nameOf(p);
    }
}

TEST(Format, NoErrorModelReadsAsNone) {
    const fs::path path = scratch() / "none.shrefract.exr";
    writeBake(path.string(), syntheticBake(Precision::F32));
    const BakeData r = readBake(path.string());
    EXPECT_EQ(r.errorOrder, -1);
    EXPECT_TRUE(r.errors.empty());
    EXPECT_FALSE(r.manifest.contains("errorModel"));
}

TEST(Format, ErrorModelOfTheWrongSizeIsRefusedBeforeWriting) {
    const fs::path path = scratch() / "bad.shrefract.exr";
    BakeData d = syntheticBake(Precision::F32);
    d.errorOrder = 2;
    d.errors.assign(5, 0.0f);
    EXPECT_THROW(writeBake(path.string(), d), std::invalid_argument);
    EXPECT_FALSE(fs::exists(path));
    EXPECT_TRUE(leftovers(path.parent_path()).empty());
}

TEST(Format, RoundTripF16WithinHalfPrecision) {
    const fs::path path = scratch() / "f16.shrefract.exr";
    const BakeData d = syntheticBake(Precision::F16);
    writeBake(path.string(), d);
    const BakeData r = readBake(path.string());
    EXPECT_EQ(r.precision, Precision::F16);
    ASSERT_EQ(r.weights.size(), d.weights.size());
    int inexact = 0;
    for (size_t v = 0; v < d.weights.size(); ++v) {
        // Round to nearest with an 11-bit significand: relative error 2^-11; subnormal halves
        // below 2^-14 are spaced 2^-24 apart.
        const float tol = std::abs(d.weights[v]) * std::ldexp(1.0f, -11) + std::ldexp(1.0f, -25);
        ASSERT_LE(std::abs(r.weights[v] - d.weights[v]), tol) << "weight " << v;
        inexact += r.weights[v] != d.weights[v];
    }
    EXPECT_GT(inexact, 0) << "the weights were not stored as half";
}

TEST(Format, RoundTripU8WithinHalfAStep) {
    const fs::path path = scratch() / "u8.shrefract.exr";
    const BakeData d = syntheticBake(Precision::U8);
    writeBake(path.string(), d);
    const BakeData r = readBake(path.string());
    EXPECT_EQ(r.precision, Precision::U8);
    const int K = d.coefficientCount();
    const size_t N = size_t(d.layout.sampleCount());
    ASSERT_EQ(r.u8Scale.size(), size_t(K) * 4);
    ASSERT_EQ(r.u8Offset.size(), size_t(K) * 4);
    ASSERT_EQ(r.weights.size(), d.weights.size());
    for (int k = 0; k < K; ++k) {
        for (int c = 0; c < 4; ++c) {
            float lo = INFINITY, hi = -INFINITY;
            size_t iLo = 0, iHi = 0;
            for (size_t i = 0; i < N; ++i) {
                const float v = d.weights[(k * N + i) * 4 + c];
                if (v < lo) lo = v, iLo = i;
                if (v > hi) hi = v, iHi = i;
            }
            const float scale = r.u8Scale[k * 4 + c];
            EXPECT_EQ(r.u8Offset[k * 4 + c], lo);
            EXPECT_NEAR(scale, (hi - lo) / 255.0f, 1e-6f * (hi - lo));
            // The extremes decode exactly, everything else within half a step.
            EXPECT_EQ(r.weights[(k * N + iLo) * 4 + c], lo) << "k " << k << " c " << c;
            EXPECT_EQ(r.weights[(k * N + iHi) * 4 + c], hi) << "k " << k << " c " << c;
            for (size_t i = 0; i < N; ++i) {
                const size_t v = (k * N + i) * 4 + c;
                ASSERT_LE(std::abs(r.weights[v] - d.weights[v]), scale * 0.5f * (1 + 1e-5f))
                    << "k " << k << " c " << c << " sample " << i;
            }
        }
    }
}

// quantizeWeights leaves in memory what the file holds: against the writer and reader (the round
// trip above), bit for bit, at every precision; and once more changes nothing (the writer refits
// the u8 scale on the rounded weights and must land on the same codes).
TEST(Format, QuantizedWeightsAreWhatTheFileHolds) {
    for (Precision p : {Precision::F32, Precision::F16, Precision::U8}) {
        const fs::path path = scratch() / ("quantized_" + std::string(nameOf(p)) + ".shrefract.exr");
        const BakeData d = syntheticBake(p);
        BakeData q = d;
        quantizeWeights(q);
        writeBake(path.string(), d);
        const BakeData r = readBake(path.string());
        ASSERT_EQ(q.weights.size(), r.weights.size());
        size_t moved = 0;
        for (size_t v = 0; v < q.weights.size(); ++v) {
            ASSERT_EQ(q.weights[v], r.weights[v]) << nameOf(p) << " weight " << v;
            moved += q.weights[v] != d.weights[v];
        }
        EXPECT_EQ(moved > 0, p != Precision::F32) << nameOf(p) << ": " << moved << " weights rounded";
        EXPECT_EQ(q.u8Scale, r.u8Scale) << nameOf(p);
        EXPECT_EQ(q.u8Offset, r.u8Offset) << nameOf(p);
        BakeData again = q;
        quantizeWeights(again);
        EXPECT_EQ(again.weights, q.weights) << nameOf(p);
        writeBake(path.string(), q);
        EXPECT_EQ(readBake(path.string()).weights, q.weights) << nameOf(p);
    }
}

TEST(Format, U8ConstantChannelDecodesExactly) {
    const fs::path path = scratch() / "u8const.shrefract.exr";
    BakeData d = syntheticBake(Precision::U8);
    const size_t N = size_t(d.layout.sampleCount());
    for (size_t i = 0; i < N; ++i) d.weights[(2 * N + i) * 4 + 1] = -0.3f;  // k 2, channel y
    writeBake(path.string(), d);
    const BakeData r = readBake(path.string());
    EXPECT_EQ(r.u8Scale[2 * 4 + 1], 0.0f);
    for (size_t i = 0; i < N; ++i) EXPECT_EQ(r.weights[(2 * N + i) * 4 + 1], -0.3f);
}

TEST(Format, ManifestKeepsCallerFieldsAndAddsLayout) {
    const fs::path dir = scratch();
    const BakeData d = syntheticBake(Precision::U8);
    writeBake((dir / "a.shrefract.exr").string(), d);
    const json m = readBake((dir / "a.shrefract.exr").string()).manifest;
    for (const char* key : {"grid", "filter", "media", "meshChecksum", "shConvention", "stats"})
        EXPECT_EQ(m.at(key), d.manifest.at(key)) << key;
    EXPECT_EQ(m.at("format"), "shrefract");
    EXPECT_EQ(m.at("version"), kFormatVersion);
    EXPECT_EQ(m.at("order"), 4);  // the caller's stale 99 is overridden
    EXPECT_EQ(m.at("coefficients"), 15);
    EXPECT_EQ(m.at("precision"), "u8");
    EXPECT_EQ(m.at("sampleCount"), 37);
    EXPECT_EQ(m.at("mu"), json::array({7, 6}));
    EXPECT_EQ(m.at("rho"), json::array({6, 12}));
    EXPECT_EQ(m.at("block"), json::array({3, 6, 2}));
    EXPECT_EQ(m.at("triangleCount"), 3);
    EXPECT_EQ(m.at("rate"), 2);
    EXPECT_EQ(m.at("neighbourListLength"), d.layout.neighbourIndex.size());
    EXPECT_EQ(m.at("neighbourListWidth"), 10);  // ceil(sqrt(91))
    EXPECT_EQ(m.at("u8").at("scale").size(), 60u);
    EXPECT_EQ(m.at("u8").at("offset").size(), 60u);

    // Not U8: no stale "u8" survives.
    BakeData f = syntheticBake(Precision::F16);
    writeBake((dir / "b.shrefract.exr").string(), f);
    const json mf = readBake((dir / "b.shrefract.exr").string()).manifest;
    EXPECT_EQ(mf.at("precision"), "f16");
    EXPECT_FALSE(mf.contains("u8"));

    // Every part carries the manifest, for tools that pull one part out.
    Imf::MultiPartInputFile file((dir / "a.shrefract.exr").c_str());
    ASSERT_EQ(file.parts(), 5);
    const std::vector<std::string> names = {"weights", "samples", "rho", "neighbours",
                                            "neighbour_list"};
    for (int p = 0; p < file.parts(); ++p) {
        EXPECT_EQ(file.header(p).name(), names[p]);
        EXPECT_EQ(file.header(p).compression(), Imf::ZIP_COMPRESSION);
        const auto* a =
            file.header(p).findTypedAttribute<Imf::StringAttribute>("shrefract.manifest");
        ASSERT_NE(a, nullptr) << names[p];
        EXPECT_EQ(json::parse(a->value()), m) << names[p];
    }
}

TEST(Format, LayoutArraysSurviveRoundTrip) {
    const fs::path dir = scratch();
    for (Precision p : {Precision::F32, Precision::F16, Precision::U8}) {
        const fs::path path = dir / (std::string(nameOf(p)) + ".shrefract.exr");
        const BakeData d = syntheticBake(p, 11);
        writeBake(path.string(), d);
        SCOPED_TRACE(nameOf(p));
        expectLayoutEqual(readBake(path.string()).layout, d.layout);
    }
}

// Chart layouts: the atlas, the unfolded mesh and the seam sources come back as written, every
// sample from its own atlas texel, at every precision.
TEST(Format, ChartLayoutRoundTrips) {
    const fs::path dir = scratch();
    for (Precision p : {Precision::F32, Precision::F16, Precision::U8}) {
        SCOPED_TRACE(nameOf(p));
        const fs::path path = dir / (std::string(nameOf(p)) + ".shrefract.exr");
        const BakeData d = syntheticChartBake(p);
        writeBake(path.string(), d);
        const BakeData r = readBake(path.string());
        expectLayoutEqual(r.layout, d.layout);
        expectAtlasEqual(r.layout.atlas, d.layout.atlas);
        EXPECT_EQ(r.manifest.at("layout").at("kind"), "isolated");  // the stale kind is replaced
        EXPECT_EQ(r.manifest.at("layout").at("method"), "lscm");    // descriptive keys stay
        EXPECT_EQ(r.manifest.at("layout").at("charts"), 2);
        if (p == Precision::F32) EXPECT_EQ(r.weights, d.weights);
    }
}

// What a third party reads with OpenEXR alone (docs/format.md): in a chart layout sample i's
// weights and position sit at the texel where rho shows sample i, not at texel i.
TEST(Format, ChartSamplesSitAtTheirAtlasTexels) {
    const fs::path path = scratch() / "chart.shrefract.exr";
    const BakeData d = syntheticChartBake(Precision::F32);
    writeBake(path.string(), d);
    Imf::MultiPartInputFile file(path.c_str());
    std::map<std::string, int> part;
    for (int p = 0; p < file.parts(); ++p) part[file.header(p).name()] = p;
    for (const char* name : {"chart_vertices", "chart_triangles", "seam_sources"})
        EXPECT_TRUE(part.count(name)) << name;
    auto readChannel = [&](const char* name, const char* channel, Imf::PixelType type) {
        std::vector<uint32_t> bytes(30);
        Imf::InputPart in(file, part.at(name));
        Imf::FrameBuffer fb;
        fb.insert(channel, Imf::Slice(type, reinterpret_cast<char*>(bytes.data()), 4, 4 * 6));
        in.setFrameBuffer(fb);
        in.readPixels(0, 4);
        return bytes;
    };
    const std::vector<uint32_t> kind = readChannel("rho", "kind", Imf::UINT);
    const std::vector<uint32_t> a = readChannel("rho", "a", Imf::UINT);
    const std::vector<uint32_t> w = readChannel("weights", "w001.z", Imf::FLOAT);
    const std::vector<uint32_t> px = readChannel("samples", "P.x", Imf::FLOAT);
    int shown = 0;
    for (int t = 0; t < 30; ++t) {
        if (kind[t] == 0) {
            float zero;
            std::memcpy(&zero, &w[t], 4);
            EXPECT_EQ(zero, 0.0f) << "texel " << t;
            continue;
        }
        ++shown;
        const uint32_t i = a[t];
        float wv, pv;
        std::memcpy(&wv, &w[t], 4);
        std::memcpy(&pv, &px[t], 4);
        EXPECT_EQ(wv, d.weights[(size_t(1) * 9 + i) * 4 + 2]) << "texel " << t;
        EXPECT_EQ(pv, d.layout.position[i].x) << "texel " << t;
    }
    EXPECT_EQ(shown, 9);
}

// Valid checksums, wrong content: each is refused with what is wrong.
TEST(Format, InconsistentChartLayoutsAreReported) {
    const fs::path dir = scratch();
    const fs::path ok = dir / "ok.shrefract.exr";
    writeBake(ok.string(), syntheticChartBake(Precision::F32));
    rewrite(ok, dir / "kind.shrefract.exr", [](json& m) { m["layout"]["kind"] = "spiral"; });
    expectInputError(dir / "kind.shrefract.exr", "unknown layout kind 'spiral'");
    // rho shows sample 3 twice (texel 0 copies texel 14's index).
    rewrite(ok, dir / "twice.shrefract.exr", [](json&) {},
            [](const std::string& p, const std::string& c, std::vector<char>& bytes) {
                if (p == "rho" && (c == "kind" || c == "a")) std::memcpy(&bytes[0], &bytes[4 * 14], 4);
            });
    expectInputError(dir / "twice.shrefract.exr", "is not one sample's own texel");
    // A triangle pointing past the vertices; a seam source taking a sample that does not exist.
    const std::tuple<const char*, const char*, uint32_t, const char*> edits[] = {
        {"chart_triangles", "c", 99, "refers to vertex 99"}, {"seam_sources", "s0", 9, "takes sample 9"}};
    for (const auto& [part, channel, value, what] : edits) {
        const fs::path bad = dir / (std::string(part) + ".shrefract.exr");
        rewrite(ok, bad, [](json&) {},
                [&, part = part, channel = channel, value = value](
                    const std::string& p, const std::string& c, std::vector<char>& bytes) {
                    if (p == part && c == channel) std::memcpy(&bytes[0], &value, 4);
                });
        expectInputError(bad, what);
    }
    // The writer refuses the same kind of thing before it opens a file.
    BakeData d = syntheticChartBake(Precision::F32);
    d.layout.atlas.vertexUV[2].x = 1.5f;
    EXPECT_THROW(writeBake((dir / "uv.shrefract.exr").string(), d), std::invalid_argument);
    EXPECT_FALSE(fs::exists(dir / "uv.shrefract.exr"));
}

TEST(Format, EmptyNeighbourListRoundTrips) {
    const fs::path path = scratch() / "noneighbours.shrefract.exr";
    BakeData d = syntheticBake(Precision::F32);
    std::fill(d.layout.neighbourCount.begin(), d.layout.neighbourCount.end(), 0u);
    std::fill(d.layout.neighbourOffset.begin(), d.layout.neighbourOffset.end(), 0u);
    d.layout.neighbourIndex.clear();
    d.layout.neighbourWeight.clear();
    writeBake(path.string(), d);
    expectLayoutEqual(readBake(path.string()).layout, d.layout);
}

TEST(Format, MissingFileIsReported) {
    expectInputError(scratch() / "nothing.shrefract.exr", "file not found");
}

TEST(Format, NonExrFileIsReported) {
    const fs::path path = scratch() / "text.shrefract.exr";
    writeFile(path, "this is a text file, not an image\n");
    expectInputError(path, "not an OpenEXR file");
}

TEST(Format, PlainExrIsNotABake) {
    const fs::path path = scratch() / "rgba.exr";
    {
        std::vector<Imf::Rgba> pixels(16, Imf::Rgba(0.5f, 0.25f, 0.125f, 1.0f));
        Imf::RgbaOutputFile out(path.c_str(), 4, 4, Imf::WRITE_RGBA);
        out.setFrameBuffer(pixels.data(), 1, 4);
        out.writePixels(4);
    }
    expectInputError(path, "not a shrefract bake");
}

TEST(Format, NewerVersionIsRejected) {
    const fs::path dir = scratch();
    writeBake((dir / "ok.shrefract.exr").string(), syntheticBake(Precision::F32));
    rewrite(dir / "ok.shrefract.exr", dir / "v2.shrefract.exr",
            [](json& m) { m["version"] = kFormatVersion + 1; });
    expectInputError(dir / "v2.shrefract.exr", "format version " +
                                                   std::to_string(kFormatVersion + 1) +
                                                   " is newer than this build reads (" +
                                                   std::to_string(kFormatVersion) + ")");
    // The copy itself is faithful: with the version left alone it reads back.
    rewrite(dir / "ok.shrefract.exr", dir / "v1.shrefract.exr", [](json&) {});
    EXPECT_NO_THROW(readBake((dir / "v1.shrefract.exr").string()));
}

TEST(Format, TruncatedFileIsReported) {
    const fs::path dir = scratch();
    writeBake((dir / "ok.shrefract.exr").string(), syntheticBake(Precision::F32));
    const std::string bytes = readFile(dir / "ok.shrefract.exr");
    writeFile(dir / "half.shrefract.exr", bytes.substr(0, bytes.size() / 2));
    expectInputError(dir / "half.shrefract.exr", "");
}

TEST(Format, InconsistentSizesAreReported) {
    const fs::path dir = scratch();
    const fs::path ok = dir / "ok.shrefract.exr";
    writeBake(ok.string(), syntheticBake(Precision::F32));
    rewrite(ok, dir / "many.shrefract.exr", [](json& m) { m["sampleCount"] = 43; });
    expectInputError(dir / "many.shrefract.exr", "do not fit the 7 x 6 mu layout");
    rewrite(ok, dir / "mu.shrefract.exr", [](json& m) { m["mu"] = {6, 7}; });
    expectInputError(dir / "mu.shrefract.exr", "data window");
    rewrite(ok, dir / "order.shrefract.exr", [](json& m) { m["order"] = 5; });
    expectInputError(dir / "order.shrefract.exr", "coefficients");
    rewrite(ok, dir / "noformat.shrefract.exr", [](json& m) { m.erase("format"); });
    expectInputError(dir / "noformat.shrefract.exr", "not a shrefract bake");
    rewrite(ok, dir / "prec.shrefract.exr", [](json& m) { m["precision"] = "f16"; });
    expectInputError(dir / "prec.shrefract.exr", "\"w000.x\" is FLOAT, expected HALF");
    // A rho texel that points past the samples, and a neighbour run past the list.
    rewrite(
        ok, dir / "rho.shrefract.exr", [](json&) {},
        [](const std::string& part, const std::string& channel, std::vector<char>& bytes) {
            const uint32_t bad = 37;
            if (part == "rho" && channel == "a") std::memcpy(&bytes[4 * 1], &bad, 4);
        });
    expectInputError(dir / "rho.shrefract.exr", "rho texel (1, 0) refers to samples (37");
    rewrite(
        ok, dir / "list.shrefract.exr", [](json&) {},
        [](const std::string& part, const std::string& channel, std::vector<char>& bytes) {
            const uint32_t bad = 91;  // count 1: runs to 92 > 91 entries
            if (part == "neighbours" && channel == "offset") std::memcpy(&bytes[4 * 36], &bad, 4);
        });
    expectInputError(dir / "list.shrefract.exr", "neighbours of sample 36");
}

// The manifest's values go through the checks shrefract-bake applies to its options and a scene
// to its media (common/limits.h, mediumProblem, gridProblem), on files whose checksums are
// right: what the bake would refuse to make is refused on reading, naming the key.
TEST(Format, ManifestValuesAreValidatedLikeTheBakeOptions) {
    const fs::path dir = scratch();
    const fs::path ok = dir / "ok.shrefract.exr";
    writeBake(ok.string(), syntheticBake(Precision::F32));
    const std::pair<std::function<void(json&)>, std::string> cases[] = {
        {[](json& m) { m["media"][0]["ior"] = 0.0; }, "media[0]: 'ior' 0 is not in [1, 5]"},
        {[](json& m) { m["media"][1]["ior"] = 7.5; }, "media[1]: 'ior' 7.5 is not in [1, 5]"},
        {[](json& m) { m["media"][2]["absorption"] = {0.1, -1.0, 0.0}; },
         "media[2]: 'absorption' has -1"},
        {[](json& m) { m["media"][0]["ior"] = "1.5"; }, "media[0]: 'ior' is not a number"},
        {[](json& m) { m["media"] = json::array({m["media"][0]}); },
         "sample 1 lies on part 1 but the manifest has 1 media"},
        {[](json& m) { m["grid"] = {32, 63}; }, "NPHI must be even"},
        {[](json& m) { m["grid"] = {1, 64}; }, "counts must lie in [2, 1024]"},
        {[](json& m) { m["maxBounces"] = 0; }, "\"maxBounces\" 0 is not in [1, 10000]"},
        {[](json& m) { m["filterWidth"] = -2.0; }, "\"filterWidth\" -2.0 is not in [0, 1000]"},
        {[](json& m) { m["branch"] = "reflect"; }, "\"branch\" \"reflect\""},
        {[](json& m) { m["order"] = 25, m["coefficients"] = 351; }, "SH order 25 is not in [0, 20]"},
        {[](json& m) { m["rate"] = 65; }, "rate 65 is not in [1, 64]"},
        {[](json& m) { m["basis"] = "table"; }, "basis"},
        {[](json& m) { m["basis"] = "grid"; }, "a grid-basis bake has SH order 0, not 4"},
        {[](json& m) { m["basis"] = "grid", m["order"] = 0; }, "manifest has no \"grid\" array"},
        {[](json& m) { m["basis"] = "grid", m["order"] = 0, m["grid"] = {32, 64}; }, "15 coefficients, grid 32x64 has 2048"},
        {[](json& m) { m["basis"] = "grid", m["order"] = 0, m["grid"] = {64, 64}; },
         "stores 4096 coefficients per sample, more than 2048"},
        {[](json& m) { m["sampleCount"] = 4294967296ll; }, "manifest has no integer \"sampleCount\""},
        {[](json& m) { m["mu"] = {40000, 1}; }, "above 32768"},
        // The list would be read past its part's pixels.
        {[](json& m) { m["neighbourListLength"] = 101; },
         "neighbour list of 101 entries does not fit its 10 x 10 part"},
    };
    int n = 0;
    for (const auto& [edit, what] : cases) {
        const fs::path bad = dir / ("bad" + std::to_string(n++) + ".shrefract.exr");
        rewrite(ok, bad, edit);
        SCOPED_TRACE(what);
        expectInputError(bad, what);
    }
}

// The layout read back is one the runtime can walk without a bounds check: every triangle's grid
// positions hold samples and its corrections lie past its hypotenuse, blocks hold two triangles,
// normals are unit, neighbour lists start with the sample and their weights sum to 1, weights are
// finite. Each broken in a file with correct checksums (and unverified) is refused.
TEST(Format, LayoutIsInternallyConsistent) {
    const fs::path dir = scratch();
    const fs::path ok = dir / "ok.shrefract.exr";
    writeBake(ok.string(), syntheticBake(Precision::F16));
    auto setU = [](std::vector<char>& bytes, size_t texel, uint32_t v) {
        std::memcpy(&bytes[4 * texel], &v, 4);
    };
    auto setF = [](std::vector<char>& bytes, size_t texel, float v) {
        std::memcpy(&bytes[4 * texel], &v, 4);
    };
    struct Case {
        std::string part, channel;
        std::function<void(std::vector<char>&)> edit;
        std::string what;
    };
    const Case cases[] = {
        // Texel (0, 0) is triangle 0's sample (0, 0); (1, 2) its correction (1, 2).
        {"rho", "kind", [&](auto& b) { setU(b, 0, RhoTexel::Empty); },
         "triangle 0's sample texel (0, 0) at rho (0, 0) has kind 0"},
        {"rho", "kind", [&](auto& b) { setU(b, 2 * 6 + 1, RhoTexel::Sample); },
         "triangle 0's correction texel (1, 2) at rho (1, 2) has kind 1"},
        {"samples", "N.x", [&](auto& b) { setF(b, 5, 3.0f); }, "sample 5 has a normal of length"},
        {"samples", "P.y", [&](auto& b) { setF(b, 6, INFINITY); }, "sample 6 has a non-finite position"},
        {"neighbour_list", "index", [&](auto& b) { setU(b, 0, 1); },
         "the neighbour list of sample 0 does not start with the sample itself"},
        {"neighbour_list", "weight", [&](auto& b) { setF(b, 0, 0.5f); },
         "the neighbour weights of sample 0 sum to 0.5"},
        {"neighbour_list", "weight", [&](auto& b) { setF(b, 3, NAN); },
         "neighbour list entry 3 has a non-finite weight"},
        {"weights", "w002.z", [&](auto& b) {
             const half inf = half::posInf();
             std::memcpy(&b[2 * 4], &inf, 2);
         }, "weight 2 of sample 4 channel z is not finite"},
    };
    int n = 0;
    for (const Case& c : cases) {
        const fs::path bad = dir / ("layout" + std::to_string(n++) + ".shrefract.exr");
        rewrite(
            ok, bad, [](json&) {},
            [&](const std::string& part, const std::string& channel, std::vector<char>& bytes) {
                if (part == c.part && channel == c.channel) c.edit(bytes);
            });
        SCOPED_TRACE(c.what);
        expectInputError(bad, "inconsistent bake: " + c.what);
        ReadOptions fast;
        fast.verify = false;
        EXPECT_THROW(readBake(bad.string(), fast), InputError);
    }
    // Blocks too small for two triangles at the rate: 2 x 6 at rate 2 (needs w, h >= 3, w + h >= 9).
    rewrite(ok, dir / "block.shrefract.exr", [](json& m) { m["block"] = {2, 6, 3}; });
    expectInputError(dir / "block.shrefract.exr", "rho blocks of 2 x 6 texels cannot hold two");
}

// Sizes beyond what the file's bytes can decode to are refused before anything is allocated: a
// file of a few kilobytes whose headers and manifest agree on a 20000 x 20000 mu layout (and hold
// no pixels) would otherwise ask for 20000^2 x (15 x 16 + 36) bytes = 110 GB.
TEST(Format, SizesBeyondTheFileAreRefusedBeforeAllocating) {
    const fs::path dir = scratch();
    const fs::path ok = dir / "ok.shrefract.exr", huge = dir / "huge.shrefract.exr";
    writeBake(ok.string(), syntheticBake(Precision::F32));
    {
        Imf::MultiPartInputFile in(ok.c_str());
        std::vector<Imf::Header> headers;
        for (int p = 0; p < in.parts(); ++p) headers.push_back(in.header(p));
        json m = json::parse(
            headers[0].typedAttribute<Imf::StringAttribute>("shrefract.manifest").value());
        m["mu"] = {20000, 20000};
        const std::string text = m.dump();
        const Imath::Box2i big({0, 0}, {19999, 19999});
        for (Imf::Header& h : headers) {
            h.displayWindow() = big;
            if (h.name() == "weights" || h.name() == "samples" || h.name() == "neighbours")
                h.dataWindow() = big;
            h.typedAttribute<Imf::StringAttribute>("shrefract.manifest").value() = text;
            h.typedAttribute<Imf::StringAttribute>("shrefract.manifestChecksum").value() =
                checksumHex(text);
        }
        Imf::MultiPartOutputFile out(huge.c_str(), headers.data(), int(headers.size()));
    }  // no pixels written: the chunk tables stay empty
    ASSERT_LT(fs::file_size(huge), 200000u);
    expectInputError(huge, "truncated or corrupt: its parts would hold");
}

TEST(Format, WriteIntoMissingDirectoryLeavesNothing) {
    const fs::path dir = scratch();
    const fs::path path = dir / "missing" / "out.shrefract.exr";
    try {
        writeBake(path.string(), syntheticBake(Precision::F32));
        FAIL() << "writeBake did not throw";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "missing"));
    EXPECT_TRUE(fs::is_empty(dir));
}

TEST(Format, FailedWriteLeavesOldFileUntouched) {
    const fs::path dir = scratch();
    const fs::path path = dir / "bake.shrefract.exr";
    writeBake(path.string(), syntheticBake(Precision::F32, 1));
    const std::string before = readFile(path);

    // Caught before the temporary file is opened: sizes that do not agree.
    BakeData sizes = syntheticBake(Precision::F32, 2);
    sizes.weights.pop_back();
    EXPECT_THROW(writeBake(path.string(), sizes), std::invalid_argument);
    BakeData rho = syntheticBake(Precision::F32, 2);
    rho.layout.rho[5] = {RhoTexel::Sample, 1000, 0, 0};
    EXPECT_THROW(writeBake(path.string(), rho), std::invalid_argument);
    EXPECT_EQ(readFile(path), before);

    // Caught midway, with the temporary file half written: a NaN weight in the last sample.
    BakeData nan = syntheticBake(Precision::F32, 2);
    nan.weights.back() = NAN;
    EXPECT_THROW(writeBake(path.string(), nan), std::invalid_argument);
    EXPECT_EQ(readFile(path), before);
    EXPECT_EQ(leftovers(dir), std::vector<std::string>{});

    // U8 finds it while fitting the scales.
    nan.precision = Precision::U8;
    EXPECT_THROW(writeBake(path.string(), nan), std::invalid_argument);
    EXPECT_EQ(readFile(path), before);
    EXPECT_EQ(leftovers(dir), std::vector<std::string>{});
}

TEST(Format, FailedRenameRemovesTemporary) {
    // Renaming a file over a non-empty directory fails after the whole file was written.
    const fs::path dir = scratch();
    const fs::path path = dir / "taken.shrefract.exr";
    fs::create_directories(path / "inside");
    try {
        writeBake(path.string(), syntheticBake(Precision::F16));
        FAIL() << "writeBake did not throw";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    }
    EXPECT_TRUE(fs::is_directory(path / "inside"));
    EXPECT_EQ(leftovers(dir), std::vector<std::string>{});
}

TEST(Format, OverwriteReplacesOldFile) {
    const fs::path path = scratch() / "bake.shrefract.exr";
    writeBake(path.string(), syntheticBake(Precision::F32, 1));
    const BakeData d = syntheticBake(Precision::F16, 2);
    writeBake(path.string(), d);
    const BakeData r = readBake(path.string());
    EXPECT_EQ(r.precision, Precision::F16);
    expectLayoutEqual(r.layout, d.layout);
}

// The sizes docs/format.md quotes: order 8 (45 coefficients), a 256 x 256 mu layout, weights that
// vary smoothly over the surface (as baked weights do, mostly) plus noise at the 8-bit step.
TEST(Format, WeightBytesPerTexelPerCoefficient) {
    const fs::path dir = scratch();
    const int W = 256, H = 256, N = W * H;
    BakeData d;
    d.order = 8;
    SurfaceLayout& L = d.layout;
    L.muWidth = W, L.muHeight = H;
    L.rhoWidth = L.rhoHeight = 1;
    L.rho.resize(1);
    L.position.resize(N);
    L.normal.assign(N, glm::vec3(0, 0, 1));
    L.part.assign(N, 0);
    L.neighbourOffset.assign(N, 0);
    L.neighbourCount.assign(N, 0);
    const int K = d.coefficientCount();
    std::mt19937 rng(3);
    std::normal_distribution<float> noise(0.0f, 1.0f / 512);
    d.weights.resize(size_t(K) * N * 4);
    for (int k = 0; k < K; ++k)
        for (int i = 0; i < N; ++i)
            for (int c = 0; c < 4; ++c) {
                const float x = float(i % W) / W, y = float(i / W) / H;
                d.weights[(size_t(k) * N + i) * 4 + c] =
                    std::sin(6.0f * x + k + c) * std::cos(4.0f * y - c) / (1 + k) + noise(rng);
            }
    // Each precision against the same bake at order 0 (one coefficient): the difference is what
    // the other 44 coefficients cost.
    BakeData order0 = d;
    order0.order = 0;
    order0.weights.resize(size_t(N) * 4);
    double perTexel[3];
    int j = 0;
    for (Precision p : {Precision::F32, Precision::F16, Precision::U8}) {
        d.precision = order0.precision = p;
        const fs::path path = dir / (std::string(nameOf(p)) + ".exr");
        const fs::path path0 = dir / (std::string(nameOf(p)) + "-order0.exr");
        writeBake(path.string(), d);
        writeBake(path0.string(), order0);
        const double size = double(fs::file_size(path)), size0 = double(fs::file_size(path0));
        perTexel[j++] = (size - size0) / (double(N) * (K - 1));
        std::printf(
            "[ sizes    ] %s: %.0f bytes (order 0: %.0f), %.3f bytes per texel per "
            "coefficient\n",
            nameOf(p), size, size0, perTexel[j - 1]);
    }
    EXPECT_GT(perTexel[0], perTexel[1]);
    EXPECT_GT(perTexel[1], perTexel[2]);
    EXPECT_LE(perTexel[0], 16.5);  // never much above the uncompressed 16 bytes
}

}  // namespace
}  // namespace shrefract

namespace shrefract {
namespace {

bool sameData(const BakeData& a, const BakeData& b) {
    return a.order == b.order && a.precision == b.precision && a.weights == b.weights &&
           a.u8Scale == b.u8Scale && a.u8Offset == b.u8Offset &&
           a.layout.position == b.layout.position && a.layout.normal == b.layout.normal &&
           a.layout.part == b.layout.part && a.layout.rho.size() == b.layout.rho.size() &&
           std::equal(a.layout.rho.begin(), a.layout.rho.end(), b.layout.rho.begin(),
                      [](const RhoTexel& x, const RhoTexel& y) {
                          return x.kind == y.kind && x.a == y.a && x.b == y.b && x.c == y.c;
                      }) &&
           a.layout.neighbourOffset == b.layout.neighbourOffset &&
           a.layout.neighbourCount == b.layout.neighbourCount &&
           a.layout.neighbourIndex == b.layout.neighbourIndex &&
           a.layout.neighbourWeight == b.layout.neighbourWeight && a.manifest == b.manifest;
}

// One value changed in one part, checksums left as written: the reader names that part. With
// verification off the same file loads (so it is the checksum that refuses it).
TEST(Format, EveryPartIsCheckedAgainstItsChecksum) {
    const fs::path dir = scratch();
    const fs::path ok = dir / "ok.shrefract.exr", okCharts = dir / "charts.shrefract.exr";
    writeBake(ok.string(), syntheticBake(Precision::F16));
    writeBake(okCharts.string(), syntheticChartBake(Precision::F32));
    const std::pair<const char*, const char*> targets[] = {
        {"weights", "w003.y"},   {"samples", "N.x"},         {"rho", "kind"},
        {"neighbours", "count"}, {"neighbour_list", "weight"}, {"chart_vertices", "u"},
        {"chart_triangles", "b"}, {"seam_sources", "w0"}};
    for (const auto& [part, channel] : targets) {
        const fs::path bad = dir / (std::string(part) + ".shrefract.exr");
        const bool chartPart = std::string(part).rfind("chart_", 0) == 0 || std::string(part) == "seam_sources";
        rewrite(
            chartPart ? okCharts : ok, bad, [](json&) {},
            [&, part = part, channel = channel](const std::string& p, const std::string& c,
                                                std::vector<char>& bytes) {
                // Flip the lowest bit of the first value (for rho, of the empty texel (0, 3)):
                // consistent, only the checksum sees it.
                if (p == part && c == channel) bytes[p == "rho" ? 4 * (3 * 6 + 0) : 0] ^= 1;
            },
            /*resign=*/false);
        expectInputError(bad, std::string("part \"") + part + "\" is corrupt");
        ReadOptions fast;
        fast.verify = false;
        EXPECT_NO_THROW(readBake(bad.string(), fast)) << part;
    }
}

TEST(Format, ManifestIsCheckedAgainstItsChecksum) {
    const fs::path dir = scratch();
    const fs::path ok = dir / "ok.shrefract.exr";
    writeBake(ok.string(), syntheticBake(Precision::F32));
    rewrite(ok, dir / "ior.shrefract.exr", [](json& m) { m["media"][0]["ior"] = 1.7; }, nullptr,
            /*resign=*/false);
    expectInputError(dir / "ior.shrefract.exr", "the manifest is corrupt");
    // Resigned, the same edit is a valid file: the checksum was the only objection.
    rewrite(ok, dir / "ior2.shrefract.exr", [](json& m) { m["media"][0]["ior"] = 1.7; });
    EXPECT_DOUBLE_EQ(readBake((dir / "ior2.shrefract.exr").string()).manifest["media"][0]["ior"], 1.7);
    // A copy in another part that disagrees with part 0's (the edit is called once per part).
    int call = 0;
    rewrite(ok, dir / "copy.shrefract.exr",
            [&](json& m) {
                if (call++ == 3) m["media"][0]["name"] = "Glass";
            },
            nullptr, /*resign=*/false);
    expectInputError(dir / "copy.shrefract.exr", "the manifest copy in part 3 differs");
}

// A file written by format version 1 (tests/data/icosphere_v1.shrefract.exr, made by the v1
// shrefract-bake: icosphere, rate 1, order 2, 8x16 grid, u8) still loads, with a warning that
// nothing in it can be verified.
TEST(Format, Version1FilesLoadUnverifiedWithAWarning) {
    const BakeData d = readBake(SHREFRACT_TEST_DATA "/icosphere_v1.shrefract.exr");
    EXPECT_EQ(d.manifest["version"], 1);
    EXPECT_EQ(d.order, 2);
    EXPECT_EQ(d.precision, Precision::U8);
    EXPECT_EQ(d.layout.sampleCount(), 642);
    EXPECT_EQ(d.layout.triangleCount, 1280);
    ASSERT_EQ(d.warnings.size(), 1u);
    EXPECT_NE(d.warnings[0].find("version 1 carries no checksums"), std::string::npos) << d.warnings[0];
    // Band 0 is the mean over the sphere of views (w_0 y_0^0): the mean of unit exit directions
    // is no longer than 1 (u8 steps allowed), and a mean path length is positive.
    const float y00 = 0.282094792f;  // y_0^0
    for (int i = 0; i < d.layout.sampleCount(); ++i) {
        const float* w = &d.weights[size_t(i) * 4];
        EXPECT_LE(glm::length(glm::vec3(w[0], w[1], w[2])) * y00, 1.0f + 1e-2f) << i;
        EXPECT_GT(w[3] * y00, 0.0f) << i;
    }
    // Written again it is version 2, verified, and the same data.
    const fs::path dir = scratch();
    writeBake((dir / "v2.shrefract.exr").string(), d);
    const BakeData again = readBake((dir / "v2.shrefract.exr").string());
    EXPECT_EQ(again.manifest["version"], kFormatVersion);
    EXPECT_TRUE(again.warnings.empty());
    EXPECT_EQ(again.weights, d.weights);
}

// Random damage, seeded: 1000 files, each with 1 to 8 bytes flipped at random places or cut
// short. Each must be refused with an InputError, or load data identical to the original (the
// flip hit bytes the data do not depend on). Never a crash, never different data.
TEST(Format, RandomCorruptionIsRefusedOrHarmless) {
    const fs::path dir = scratch();
    const fs::path ok = dir / "ok.shrefract.exr";
    for (Precision precision : {Precision::F32, Precision::U8}) {
        writeBake(ok.string(), syntheticBake(precision));
        const BakeData original = readBake(ok.string());
        const std::string bytes = readFile(ok);
        std::mt19937 rng(precision == Precision::F32 ? 1 : 2);
        int refused = 0, harmless = 0, truncations = 0;
        for (int trial = 0; trial < 500; ++trial) {
            std::string damaged = bytes;
            if (trial % 10 == 9) {
                damaged.resize(std::uniform_int_distribution<size_t>(0, bytes.size() - 1)(rng));
                ++truncations;
            } else {
                const int flips = std::uniform_int_distribution<int>(1, 8)(rng);
                for (int f = 0; f < flips; ++f) {
                    const size_t at = std::uniform_int_distribution<size_t>(0, bytes.size() - 1)(rng);
                    damaged[at] = char(damaged[at] ^ (1 << std::uniform_int_distribution<int>(0, 7)(rng)));
                }
            }
            const fs::path bad = dir / "bad.shrefract.exr";
            writeFile(bad, damaged);
            try {
                const BakeData d = readBake(bad.string());
                EXPECT_TRUE(sameData(d, original)) << "trial " << trial << " loaded different data";
                ++harmless;
            } catch (const InputError& e) {
                EXPECT_NE(std::string(e.what()).find(bad.string()), std::string::npos) << e.what();
                ++refused;
            }
        }
        std::printf("[ damage   ] %s: %d refused, %d harmless (%d truncations)\n", nameOf(precision),
                    refused, harmless, truncations);
        EXPECT_EQ(refused + harmless, 500);
        EXPECT_GT(refused, 400);  // most bytes of a small file are data, offsets or the manifest
    }
}

}  // namespace
}  // namespace shrefract
