// NAME.shrefract.exr: one multi-part OpenEXR file (layout in docs/format.md).
//
// Parts, all scanline, ZIP, data window (0,0)-(w-1,h-1), looked up by name:
//   "weights"         mu layout   w###.x/.y/.z/.len (FLOAT or HALF), or w###.rgba8 (UINT, U8)
//   "samples"         mu layout   P.x P.y P.z N.x N.y N.z (FLOAT), part (UINT)
//   "rho"             rho layout  kind a b c (UINT)
//   "neighbours"      mu layout   offset count (UINT)
//   "neighbour_list"  near-square index (UINT), weight (FLOAT); entry e at (e % w, e / w)
// Chart layouts (isolated, uv) add three near-square lists and put sample i at its atlas texel:
//   "chart_vertices"  P.x P.y P.z N.x N.y N.z u v (FLOAT), chart (UINT)
//   "chart_triangles" a b c (UINT)
//   "seam_sources"    texel s0 s1 s2 s3 (UINT), w0 w1 w2 w3 (FLOAT)
// Bakes with an error model (version 3, manifest "errorModel") add, sample i where the weights are:
//   "error"           mu layout   e### (FLOAT), the SH of ln(the fit's angular error + 0.01 rad)
// The JSON manifest sits in the string attribute "shrefract.manifest" of every part, its XXH3-64
// in "shrefract.manifestChecksum"; the manifest's "checksums" hold each part's (version 2).
#include <Iex.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfStringAttribute.h>
#include <half.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "common/bakefile.h"
#include "common/checksum.h"
#include "common/direction_grid.h"
#include "common/error.h"
#include "common/exr_input.h"
#include "common/exr_output.h"
#include "common/limits.h"
#include "common/output.h"
#include "common/scene.h"
#include "common/sh.h"

namespace shrefract {

const char* ToString(Precision p) {
    switch (p) {
        case Precision::F32:
            return "f32";
        case Precision::F16:
            return "f16";
        case Precision::U8:
            return "u8";
    }
    return "unknown";
}

Precision parsePrecision(const std::string& text) {
    if (text == "f32") return Precision::F32;
    if (text == "f16") return Precision::F16;
    if (text == "u8") return Precision::U8;
    throw InputError("unknown weight precision \"" + text + "\" (expected f32, f16 or u8)");
}

int BakeData::coefficientCount() const { return shEvenCount(order); }
int BakeData::errorCoefficientCount() const { return errorOrder < 0 ? 0 : shEvenCount(errorOrder); }

namespace {

using nlohmann::json;

constexpr const char* kManifestAttribute = "shrefract.manifest";
constexpr const char* kManifestChecksumAttribute = "shrefract.manifestChecksum";
constexpr const char* kChecksumAlgorithm = "xxh3-64";
constexpr const char* kWeightsPart = "weights";
constexpr const char* kSamplesPart = "samples";
constexpr const char* kRhoPart = "rho";
constexpr const char* kNeighboursPart = "neighbours";
constexpr const char* kNeighbourListPart = "neighbour_list";
constexpr const char* kChartVerticesPart = "chart_vertices";
constexpr const char* kChartTrianglesPart = "chart_triangles";
constexpr const char* kSeamSourcesPart = "seam_sources";
constexpr const char* kErrorPart = "error";
constexpr const char* kErrorModelKey = "errorModel";
const uint64_t kMaxErrorTexelValues = uint64_t(shEvenCount(limits::kMaxErrorOrder));
constexpr uint32_t kNoSample = UINT32_MAX;
// Rows staged per writePixels/readPixels call for the weights part (a ZIP block is 16 lines), so
// that the weights are never duplicated in memory at full size.
constexpr int kChunkRows = 16;
constexpr const char* kWeightSuffix[4] = {"x", "y", "z", "len"};

std::string weightChannel(int k, const char* suffix) {
    char name[32];
    std::snprintf(name, sizeof name, "w%03d.%s", k, suffix);
    return name;
}

// ---------------------------------------------------------------------------------------------
// Staging: the channels of one part (or of a band of rows of it), interleaved per texel.

struct Channel {
    std::string name;
    Imf::PixelType type;
};

size_t pixelSize(Imf::PixelType t) { return t == Imf::HALF ? 2 : 4; }
const char* pixelTypeName(Imf::PixelType t) {
    return t == Imf::UINT    ? "UINT"
           : t == Imf::HALF  ? "HALF"
           : t == Imf::FLOAT ? "FLOAT"
                             : "unknown";
}

class Planes {
public:
    Planes(int width, int rows, std::vector<Channel> channels)
        : width_(width), rows_(rows), channels_(std::move(channels)) {
        for (const Channel& c : channels_) {
            offset_.push_back(stride_);
            stride_ += pixelSize(c.type);
        }
        bytes_.assign(size_t(width_) * rows_ * stride_, 0);
    }
    // Texel t counts row-major from the first staged row.
    void setU(size_t t, int c, uint32_t v) { std::memcpy(at(t, c), &v, 4); }
    void setF(size_t t, int c, float v) { std::memcpy(at(t, c), &v, 4); }
    void setH(size_t t, int c, float v) {
        half h(v);
        std::memcpy(at(t, c), &h, 2);
    }
    uint32_t u(size_t t, int c) const {
        uint32_t v;
        std::memcpy(&v, at(t, c), 4);
        return v;
    }
    float f(size_t t, int c) const {
        float v;
        std::memcpy(&v, at(t, c), 4);
        return v;
    }
    float h(size_t t, int c) const {
        half v;
        std::memcpy(&v, at(t, c), 2);
        return float(v);
    }
    // A frame buffer whose row y0 is the first staged row.
    Imf::FrameBuffer frameBuffer(int y0) {
        const size_t yStride = stride_ * width_;
        Imf::FrameBuffer fb;
        for (size_t c = 0; c < channels_.size(); ++c) {
            char* base = reinterpret_cast<char*>(bytes_.data()) + offset_[c] -
                         static_cast<std::ptrdiff_t>(y0) * static_cast<std::ptrdiff_t>(yStride);
            fb.insert(channels_[c].name, Imf::Slice(channels_[c].type, base, stride_, yStride));
        }
        return fb;
    }
    const std::vector<Channel>& channels() const { return channels_; }
    // The staged bytes: texels row-major, each texel's channels in the order given, each value
    // little-endian in its pixel type's size. What a part's checksum is taken over.
    const std::vector<unsigned char>& bytes() const { return bytes_; }

private:
    unsigned char* at(size_t t, int c) { return bytes_.data() + t * stride_ + offset_[c]; }
    const unsigned char* at(size_t t, int c) const {
        return bytes_.data() + t * stride_ + offset_[c];
    }
    int width_, rows_;
    std::vector<Channel> channels_;
    std::vector<size_t> offset_;
    size_t stride_ = 0;
    std::vector<unsigned char> bytes_;
};

std::vector<Channel> weightChannels(int K, Precision p) {
    std::vector<Channel> ch;
    for (int k = 0; k < K; ++k) {
        if (p == Precision::U8) {
            ch.push_back({weightChannel(k, "rgba8"), Imf::UINT});
        } else {
            for (const char* s : kWeightSuffix)
                ch.push_back({weightChannel(k, s), p == Precision::F16 ? Imf::HALF : Imf::FLOAT});
        }
    }
    return ch;
}
// The error model's channels: e000, e001, ... one FLOAT per coefficient.
std::vector<Channel> errorChannels(int Ke) {
    std::vector<Channel> ch;
    for (int k = 0; k < Ke; ++k) {
        char name[32];
        std::snprintf(name, sizeof name, "e%03d", k);
        ch.push_back({name, Imf::FLOAT});
    }
    return ch;
}
// Bytes of one weights texel: 16 per coefficient in f32, 8 in f16, 4 in u8.
uint64_t weightsTexelBytes(int K, Precision p) {
    return uint64_t(K) * (p == Precision::U8 ? 4 : p == Precision::F16 ? 8 : 16);
}
const std::vector<Channel> kSampleChannels = {
    {"P.x", Imf::FLOAT}, {"P.y", Imf::FLOAT}, {"P.z", Imf::FLOAT}, {"N.x", Imf::FLOAT},
    {"N.y", Imf::FLOAT}, {"N.z", Imf::FLOAT}, {"part", Imf::UINT}};
const std::vector<Channel> kRhoChannels = {
    {"kind", Imf::UINT}, {"a", Imf::UINT}, {"b", Imf::UINT}, {"c", Imf::UINT}};
const std::vector<Channel> kNeighbourChannels = {{"offset", Imf::UINT}, {"count", Imf::UINT}};
const std::vector<Channel> kNeighbourListChannels = {{"index", Imf::UINT}, {"weight", Imf::FLOAT}};
const std::vector<Channel> kChartVertexChannels = {
    {"P.x", Imf::FLOAT}, {"P.y", Imf::FLOAT}, {"P.z", Imf::FLOAT}, {"N.x", Imf::FLOAT},
    {"N.y", Imf::FLOAT}, {"N.z", Imf::FLOAT}, {"u", Imf::FLOAT},   {"v", Imf::FLOAT},
    {"chart", Imf::UINT}};
const std::vector<Channel> kChartTriangleChannels = {
    {"a", Imf::UINT}, {"b", Imf::UINT}, {"c", Imf::UINT}};
const std::vector<Channel> kSeamSourceChannels = {
    {"texel", Imf::UINT}, {"s0", Imf::UINT},  {"s1", Imf::UINT},  {"s2", Imf::UINT},
    {"s3", Imf::UINT},    {"w0", Imf::FLOAT}, {"w1", Imf::FLOAT}, {"w2", Imf::FLOAT},
    {"w3", Imf::FLOAT}};

// Which sample each mu texel holds (kNoSample: none), for chart layouts, where sample i sits at
// its atlas texel; joining layouts address sample i = texel index directly.
std::vector<uint32_t> texelSamples(const SurfaceLayout& L) {
    std::vector<uint32_t> map(size_t(L.muWidth) * L.muHeight, kNoSample);
    for (size_t i = 0; i < L.atlas.sampleTexel.size(); ++i) map[L.atlas.sampleTexel[i]] = uint32_t(i);
    return map;
}

// ---------------------------------------------------------------------------------------------
// 8-bit weights: value = scale * code + offset, per coefficient k and channel c.

// Scale and offset are kept in double precision (the manifest stores them as JSON numbers) and
// the decode rounds to float once, so that code 0 gives the minimum and code 255 the maximum
// exactly. (With a float scale lo + 255 * scale lands on a grid about two float ulps apart and
// often misses the maximum.)
float dequantU8(double scale, double offset, uint32_t code) {
    return static_cast<float>(scale * double(code) + offset);
}

// (hi - lo) / 255, nudged by a few double ulps should code 255 not decode to hi exactly.
double fitScale(float lo, float hi) {
    if (!(hi > lo)) return 0.0;  // constant channel: every code decodes to lo
    const double s = (double(hi) - double(lo)) / 255.0;
    double up = s, down = s;
    for (int step = 0; step < 16; ++step) {
        if (dequantU8(up, lo, 255) == hi) return up;
        if (dequantU8(down, lo, 255) == hi) return down;
        up = std::nextafter(up, INFINITY);
        down = std::nextafter(down, 0.0);
    }
    return s;
}

uint32_t quantU8(float v, double scale, double offset) {
    if (scale == 0.0) return 0;
    const double code = std::nearbyint((double(v) - offset) / scale);
    return static_cast<uint32_t>(std::clamp(code, 0.0, 255.0));
}

struct U8Params {
    std::vector<double> scale, offset;  // [k * 4 + c]
};

U8Params fitU8(const BakeData& d) {
    const int K = d.coefficientCount();
    const size_t N = d.layout.position.size();
    U8Params q;
    q.scale.assign(size_t(K) * 4, 0.0);
    q.offset.assign(size_t(K) * 4, 0.0);
    for (int k = 0; k < K; ++k) {
        for (int c = 0; c < 4; ++c) {
            float lo = INFINITY, hi = -INFINITY;
            for (size_t i = 0; i < N; ++i) {
                const float v = d.weights[(size_t(k) * N + i) * 4 + c];
                if (!std::isfinite(v)) {
                    throw std::invalid_argument("writeBake: weight " + std::to_string(k) +
                                                " of sample " + std::to_string(i) + " channel " +
                                                kWeightSuffix[c] + " is not finite");
                }
                lo = std::min(lo, v);
                hi = std::max(hi, v);
            }
            if (N == 0) lo = hi = 0.0f;
            q.offset[k * 4 + c] = lo;
            q.scale[k * 4 + c] = fitScale(lo, hi);
        }
    }
    return q;
}

// ---------------------------------------------------------------------------------------------
// Consistency of a BakeData, shared by writer (a caller bug: std::invalid_argument) and reader
// (a bad file: InputError). Returns what is wrong, or "" when consistent.

template <class... T>
std::string str(const T&... parts) {
    std::ostringstream os;
    (os << ... << parts);
    return os.str();
}

// The chart atlas of an isolated or uv layout: rho is the atlas, every sample shown by exactly
// one Sample texel, which is its sampleTexel; the unfolded mesh and the seam sources in range.
std::string chartInconsistency(const SurfaceLayout& L) {
    const ChartAtlas& A = L.atlas;
    const size_t N = L.position.size(), texels = size_t(L.muWidth) * L.muHeight;
    if (L.rhoWidth != L.muWidth || L.rhoHeight != L.muHeight)
        return str("chart layout with rho ", L.rhoWidth, " x ", L.rhoHeight, " unlike its atlas ",
                   L.muWidth, " x ", L.muHeight);
    if (A.sampleTexel.size() != N)
        return str(A.sampleTexel.size(), " sample texels for ", N, " samples");
    std::vector<char> seen(N, 0);
    size_t shown = 0;
    for (size_t t = 0; t < L.rho.size() && t < texels; ++t) {
        const RhoTexel& r = L.rho[t];
        if (r.kind == RhoTexel::Empty) continue;
        if (r.kind != RhoTexel::Sample || r.a >= N || seen[r.a] || A.sampleTexel[r.a] != t)
            return str("atlas texel (", t % size_t(L.muWidth), ", ", t / size_t(L.muWidth),
                       ") is not one sample's own texel (kind ", r.kind, ", sample ", r.a, ")");
        seen[r.a] = 1;
        ++shown;
    }
    if (shown != N) return str("the atlas shows ", shown, " of ", N, " samples");
    const size_t V = A.vertexPosition.size();
    if (A.vertexNormal.size() != V || A.vertexUV.size() != V || A.vertexChart.size() != V)
        return str("chart vertex arrays differ in size: ", V, " positions, ", A.vertexNormal.size(),
                   " normals, ", A.vertexUV.size(), " uvs, ", A.vertexChart.size(), " charts");
    if (A.gutter < 0) return str("gutter ", A.gutter, " is negative");
    if (size_t(L.triangleCount) != A.triangles.size())
        return str("triangle count ", L.triangleCount, " but ", A.triangles.size(), " chart triangles");
    if (A.chartCount < 1) return str(A.chartCount, " charts");
    for (size_t v = 0; v < V; ++v) {
        const glm::vec2 uv = A.vertexUV[v];
        if (!(uv.x >= 0.0f && uv.x <= 1.0f && uv.y >= 0.0f && uv.y <= 1.0f))
            return str("chart vertex ", v, " has uv (", uv.x, ", ", uv.y, ") outside [0, 1]");
        if (A.vertexChart[v] >= uint32_t(A.chartCount))
            return str("chart vertex ", v, " is in chart ", A.vertexChart[v], " of ", A.chartCount);
    }
    for (size_t t = 0; t < A.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k)
            if (A.triangles[t][k] >= V)
                return str("chart triangle ", t, " refers to vertex ", A.triangles[t][k],
                           " but there are only ", V);
    for (size_t e = 0; e < A.seam.size(); ++e) {
        const SeamSource& s = A.seam[e];
        if (s.texel >= texels) return str("seam source ", e, " fills texel ", s.texel, " outside the atlas");
        for (int k = 0; k < 4; ++k)
            if (s.weight[k] != 0.0f && (s.sample[k] >= N || !std::isfinite(s.weight[k])))
                return str("seam source ", e, " takes sample ", s.sample[k], " with weight ",
                           s.weight[k], " (", N, " samples)");
    }
    return "";
}

std::string inconsistency(const BakeData& d) {
    const SurfaceLayout& L = d.layout;
    if (d.order < 0 || d.order > limits::kMaxOrder)
        return str("SH order ", d.order, " is not in [0, ", limits::kMaxOrder, "]");
    const size_t K = size_t(d.coefficientCount());
    const size_t N = L.position.size();
    if (L.normal.size() != N || L.part.size() != N)
        return str("per-sample arrays differ in size: position ", N, ", normal ", L.normal.size(),
                   ", part ", L.part.size());
    if (d.errorOrder < -1 || d.errorOrder > limits::kMaxErrorOrder)
        return str("error model order ", d.errorOrder, " is not in [-1, ", limits::kMaxErrorOrder, "]");
    if (d.errors.size() != size_t(d.errorCoefficientCount()) * N)
        return str(d.errors.size(), " error model values, expected ", d.errorCoefficientCount(),
                   " coefficients x ", N, " samples");
    if (L.muWidth < 1 || L.muHeight < 1)
        return str("mu layout is ", L.muWidth, " x ", L.muHeight, " texels");
    if (N > size_t(L.muWidth) * size_t(L.muHeight))
        return str(N, " samples do not fit the ", L.muWidth, " x ", L.muHeight, " mu layout");
    if (L.rhoWidth < 1 || L.rhoHeight < 1)
        return str("rho layout is ", L.rhoWidth, " x ", L.rhoHeight, " texels");
    if (L.rho.size() != size_t(L.rhoWidth) * size_t(L.rhoHeight))
        return str("rho has ", L.rho.size(), " texels, expected ", L.rhoWidth, " x ", L.rhoHeight);
    if (L.isChartLayout()) {
        const std::string chart = chartInconsistency(L);
        if (!chart.empty()) return chart;
    } else if (L.rate < 1 || L.rate > limits::kMaxRate) {
        return str("rate ", L.rate, " is not in [1, ", limits::kMaxRate, "]");
    }
    for (int side : {L.muWidth, L.muHeight, L.rhoWidth, L.rhoHeight})
        if (side > limits::kMaxTextureSize)
            return str("a layout side of ", side, " texels is above ", limits::kMaxTextureSize);
    if (L.triangleCount < 0) return str("triangle count ", L.triangleCount, " is negative");
    if (L.triangleCount > 0 && !L.isChartLayout()) {
        if (L.blockWidth < 1 || L.blockHeight < 1 || L.blocksPerRow < 1)
            return str("rho blocks are ", L.blockWidth, " x ", L.blockHeight, ", ", L.blocksPerRow,
                       " per row");
        const int64_t blocks = (int64_t(L.triangleCount) + 1) / 2;
        const int64_t blockRows = (blocks + L.blocksPerRow - 1) / L.blocksPerRow;
        if (int64_t(L.blocksPerRow) * L.blockWidth > L.rhoWidth ||
            blockRows * L.blockHeight > L.rhoHeight)
            return str(L.triangleCount, " triangles in ", L.blockWidth, " x ", L.blockHeight,
                       " blocks, ", L.blocksPerRow, " per row, do not fit the ", L.rhoWidth, " x ",
                       L.rhoHeight, " rho layout");
        // A block holds an upright triangle's samples (i + j <= r) and corrections (r + 1), and
        // its rotated partner's, without the two meeting (docs/format.md "rho").
        const int r = L.rate;
        if (L.blockWidth < r + 1 || L.blockHeight < r + 1 || L.blockWidth + L.blockHeight < 2 * r + 5)
            return str("rho blocks of ", L.blockWidth, " x ", L.blockHeight,
                       " texels cannot hold two triangles at rate ", r);
        if (N == 0) return str(L.triangleCount, " triangles but no samples");
    }
    for (size_t t = 0; t < L.rho.size(); ++t) {
        const RhoTexel& r = L.rho[t];
        const int x = int(t % size_t(L.rhoWidth)), y = int(t / size_t(L.rhoWidth));
        if (r.kind > RhoTexel::Correction)
            return str("rho texel (", x, ", ", y, ") has unknown kind ", r.kind);
        const bool bad = (r.kind == RhoTexel::Sample && r.a >= N) ||
                         (r.kind == RhoTexel::Correction && (r.a >= N || r.b >= N || r.c >= N));
        if (bad)
            return str("rho texel (", x, ", ", y, ") refers to samples (", r.a, ", ", r.b, ", ",
                       r.c, ") but there are only ", N);
    }
    // Every triangle's grid positions hold its samples, and the texels past its hypotenuse its
    // corrections: what the runtime and queryBake look up (SurfaceLayout::sampleAt). Chart
    // layouts have no triangle blocks (chartInconsistency checks their atlas).
    for (int t = 0; t < (L.isChartLayout() ? 0 : L.triangleCount); ++t) {
        for (int j = 0; j <= L.rate + 1; ++j)
            for (int i = 0; i + j <= L.rate + 1; ++i) {
                const bool correction = i + j == L.rate + 1;
                if (correction && (i == 0 || j == 0)) continue;
                const glm::ivec2 x = L.rhoTexel(t, i, j);
                const uint32_t kind = L.rho[size_t(x.y) * size_t(L.rhoWidth) + size_t(x.x)].kind;
                if (kind != (correction ? RhoTexel::Correction : RhoTexel::Sample))
                    return str("triangle ", t, "'s ", correction ? "correction" : "sample",
                               " texel (", i, ", ", j, ") at rho (", x.x, ", ", x.y,
                               ") has kind ", kind);
            }
    }
    for (size_t i = 0; i < N; ++i) {
        const glm::vec3 p = L.position[i], n = L.normal[i];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            return str("sample ", i, " has a non-finite position");
        const float len = glm::length(n);
        if (!(std::fabs(len - 1.0f) < 1e-3f))
            return str("sample ", i, " has a normal of length ", len, ", not a unit vector");
    }
    if (L.neighbourOffset.size() != N || L.neighbourCount.size() != N)
        return str("neighbour offsets (", L.neighbourOffset.size(), ") and counts (",
                   L.neighbourCount.size(), ") are not one per sample (", N, ")");
    const size_t E = L.neighbourIndex.size();
    if (L.neighbourWeight.size() != E)
        return str(E, " neighbour indices but ", L.neighbourWeight.size(), " weights");
    for (size_t i = 0; i < N; ++i) {
        if (uint64_t(L.neighbourOffset[i]) + L.neighbourCount[i] > E)
            return str("neighbours of sample ", i, " (offset ", L.neighbourOffset[i], ", count ",
                       L.neighbourCount[i], ") run past the list of ", E);
    }
    for (size_t e = 0; e < E; ++e) {
        if (L.neighbourIndex[e] >= N)
            return str("neighbour list entry ", e, " refers to sample ", L.neighbourIndex[e],
                       " but there are only ", N);
        if (!std::isfinite(L.neighbourWeight[e]))
            return str("neighbour list entry ", e, " has a non-finite weight");
    }
    // Smoothing averages a sample with its neighbours: itself first, weights summing to 1.
    for (size_t i = 0; i < N; ++i) {
        if (L.neighbourCount[i] == 0) continue;
        if (L.neighbourIndex[L.neighbourOffset[i]] != i)
            return str("the neighbour list of sample ", i, " does not start with the sample itself");
        double sum = 0;
        for (uint32_t k = 0; k < L.neighbourCount[i]; ++k)
            sum += L.neighbourWeight[L.neighbourOffset[i] + k];
        if (!(std::fabs(sum - 1.0) < 1e-3))
            return str("the neighbour weights of sample ", i, " sum to ", sum, ", not 1");
    }
    if (d.weights.size() != K * N * 4)
        return str(d.weights.size(), " weights, expected ", K, " coefficients x ", N,
                   " samples x 4");
    for (size_t v = 0; v < d.weights.size(); ++v)
        if (!std::isfinite(d.weights[v]))
            return str("weight ", v / (4 * N), " of sample ", (v / 4) % N, " channel ",
                       kWeightSuffix[v % 4], " is not finite");
    return "";
}

// Near-square: width ceil(sqrt(E)), at least one texel.
std::pair<int, int> neighbourListSize(size_t E) {
    if (E == 0) return {1, 1};
    int w = static_cast<int>(std::ceil(std::sqrt(double(E))));
    while (size_t(w) * size_t(w) < E) ++w;
    const int h = static_cast<int>((E + size_t(w) - 1) / size_t(w));
    return {w, h};
}

// ---------------------------------------------------------------------------------------------
// Writing.

Imf::Header partHeader(const char* name, int width, int height, const Imath::Box2i& display,
                       const std::string& manifest,
                       Imf::Compression compression = Imf::ZIP_COMPRESSION) {
    Imf::Header h(width, height);
    h.displayWindow() = display;  // shared by all parts of a multi-part file
    h.setName(name);
    h.setType(Imf::SCANLINEIMAGE);
    h.compression() = compression;
    h.insert(kManifestAttribute, Imf::StringAttribute(manifest));
    h.insert(kManifestChecksumAttribute, Imf::StringAttribute(checksumHex(manifest)));
    return h;
}

void addChannels(Imf::Header& h, const std::vector<Channel>& channels) {
    for (const Channel& c : channels) h.channels().insert(c.name, Imf::Channel(c.type));
}

void writeWhole(Imf::MultiPartOutputFile& file, int part, Planes& planes, int height) {
    Imf::OutputPart out(file, part);
    out.setFrameBuffer(planes.frameBuffer(0));
    out.writePixels(height);
}

uint32_t sampleOfTexel(const uint32_t* map, size_t texel, size_t N);

// The error model's part: errors[k * N + i] at sample i's texel (`map` as for the weights).
Planes errorPlanes(const float* errors, size_t N, int Ke, int width, int height, const uint32_t* map) {
    Planes p(width, height, errorChannels(Ke));
    for (size_t t = 0; t < size_t(width) * height; ++t) {
        const uint32_t i = sampleOfTexel(map, t, N);
        if (i == kNoSample) continue;
        for (int k = 0; k < Ke; ++k) {
            const float e = errors[size_t(k) * N + i];
            if (!std::isfinite(e))
                throw std::invalid_argument(str("error model value ", k, " of sample ", i, " is not finite"));
            p.setF(t, k, e);
        }
    }
    return p;
}

// The manifest's "errorModel" object: what the part holds and how to read it.
json errorModelInfo(int order) {
    return {{"order", order},
            {"coefficients", shEvenCount(order)},
            {"quantity", "ln(angle + offset), the angle in radians between the fitted and the traced exit"},
            {"offset", kErrorOffset},
            {"unit", "radians"}};
}

// The sample at texel `texel` (kNoSample: none): `map` for chart layouts (texelSamples), else
// the texel index itself while below the sample count.
uint32_t sampleOfTexel(const uint32_t* map, size_t texel, size_t N) {
    if (map) return map[texel];
    return texel < N ? uint32_t(texel) : kNoSample;
}

// The weights of N samples as a part stores them, K coefficients of 4 channels each; in memory
// weights[(k * N + i) * 4 + c] (BakeData::weights). Sample i sits at texel i (i % width,
// i / width), or for chart layouts where `map` (texel -> sample, kNoSample for none) puts it.
struct WeightsPart {
    const float* data;
    size_t N;
    int K;
    Precision precision;
    int width, height;
    const uint32_t* map = nullptr;
};

WeightsPart weightsPart(const BakeData& d, const std::vector<uint32_t>& map) {
    return {d.weights.data(), d.layout.position.size(), d.coefficientCount(), d.precision,
            d.layout.muWidth, d.layout.muHeight, map.empty() ? nullptr : map.data()};
}

// Rows y0 .. y0 + rows - 1 of the weights part, quantized to its precision.
Planes weightChunk(const WeightsPart& d, const U8Params& u8, int y0, int rows) {
    const int K = d.K;
    const size_t N = d.N;
    Planes chunk(d.width, rows, weightChannels(K, d.precision));
    for (size_t t = 0; t < size_t(d.width) * rows; ++t) {
        const uint32_t i = sampleOfTexel(d.map, size_t(y0) * d.width + t, N);
        if (i == kNoSample) continue;  // texels without a sample stay zero
        for (int k = 0; k < K; ++k) {
            const float* w = &d.data[(size_t(k) * N + i) * 4];
            if (d.precision == Precision::U8) {
                uint32_t packed = 0;
                for (int c = 0; c < 4; ++c)
                    packed |= quantU8(w[c], u8.scale[k * 4 + c], u8.offset[k * 4 + c]) << (8 * c);
                chunk.setU(t, k, packed);
                continue;
            }
            for (int c = 0; c < 4; ++c) {
                if (!std::isfinite(w[c]))
                    throw std::invalid_argument(str("writeBake: weight ", k, " of sample ", i,
                                                    " channel ", kWeightSuffix[c],
                                                    " is not finite"));
                if (d.precision == Precision::F16)
                    chunk.setH(t, k * 4 + c, w[c]);
                else
                    chunk.setF(t, k * 4 + c, w[c]);
            }
        }
    }
    return chunk;
}

// The checksum of the whole weights part, chunk by chunk as it will be written.
std::string weightsChecksum(const WeightsPart& d, const U8Params& u8) {
    Checksum sum;
    for (int y0 = 0; y0 < d.height; y0 += kChunkRows) {
        const Planes chunk = weightChunk(d, u8, y0, std::min(kChunkRows, d.height - y0));
        sum.update(chunk.bytes().data(), chunk.bytes().size());
    }
    return sum.hex();
}

void writeWeights(Imf::MultiPartOutputFile& file, int part, const WeightsPart& d, const U8Params& u8) {
    Imf::OutputPart out(file, part);
    for (int y0 = 0; y0 < d.height; y0 += kChunkRows) {
        const int rows = std::min(kChunkRows, d.height - y0);
        Planes chunk = weightChunk(d, u8, y0, rows);
        out.setFrameBuffer(chunk.frameBuffer(y0));
        out.writePixels(rows);
    }
}

// ---------------------------------------------------------------------------------------------
// Reading.

bool fitsInt(const json& x) {
    if (!x.is_number_integer()) return false;
    if (x.is_number_unsigned()) return x.get<uint64_t>() <= uint64_t(INT32_MAX);
    return x.get<int64_t>() >= INT32_MIN && x.get<int64_t>() <= INT32_MAX;
}

int manifestInt(const json& m, const char* key) {
    auto it = m.find(key);
    if (it == m.end() || !fitsInt(*it))
        throw InputError(str("manifest has no integer \"", key, "\""));
    return it->get<int>();
}

std::vector<int> manifestInts(const json& m, const char* key, size_t n) {
    auto it = m.find(key);
    if (it == m.end() || !it->is_array() || it->size() != n)
        throw InputError(str("manifest has no \"", key, "\" array of ", n, " integers"));
    std::vector<int> v;
    for (const json& x : *it) {
        if (!fitsInt(x))
            throw InputError(str("manifest has no \"", key, "\" array of ", n, " integers"));
        v.push_back(x.get<int>());
    }
    return v;
}

std::vector<double> manifestNumbers(const json& m, const char* key, size_t n) {
    if (!m.is_object() || !m.contains(key) || !m[key].is_array() || m[key].size() != n)
        throw InputError(str("manifest has no u8 \"", key, "\" array of ", n, " numbers"));
    std::vector<double> v;
    for (const json& x : m[key]) {
        if (!x.is_number() || !std::isfinite(x.get<double>()))
            throw InputError(str("manifest u8 \"", key, "\" holds a non-number"));
        v.push_back(x.get<double>());
    }
    return v;
}

// The descriptive keys that tools act on (evaluation re-traces with the media, grid, branch and
// bounce cap; the runtime shades with media[0]), checked as shrefract-bake checks its options and
// a scene its media (common/limits.h, mediumProblem): a manifest that says IOR 0 is refused, not
// rendered as a mirror. Keys a bake may lack are checked only when present. Returns what is
// wrong, or "".
std::string manifestProblem(const json& m) {
    if (auto it = m.find("media"); it != m.end()) {
        if (!it->is_array()) return "\"media\" is not an array";
        for (size_t i = 0; i < it->size(); ++i) {
            const json& md = (*it)[i];
            const std::string where = str("media[", i, "]");
            if (!md.is_object()) return where + " is not an object";
            Medium medium;
            if (md.contains("ior")) {
                if (!md["ior"].is_number()) return where + ": 'ior' is not a number";
                medium.ior = md["ior"].get<double>();
            }
            if (md.contains("absorption")) {
                const json& a = md["absorption"];
                if (!a.is_array() || a.size() != 3) return where + ": 'absorption' is not 3 numbers";
                for (int c = 0; c < 3; ++c) {
                    if (!a[c].is_number()) return where + ": 'absorption' is not 3 numbers";
                    medium.absorption[c] = a[c].get<double>();
                }
            }
            if (md.contains("priority") && !md["priority"].is_number_integer())
                return where + ": 'priority' is not an integer";
            for (const char* key : {"name", "mesh", "meshChecksum"})
                if (md.contains(key) && !md[key].is_string())
                    return str(where, ": '", key, "' is not a string");
            const std::string problem = mediumProblem(medium);
            if (!problem.empty()) return where + ": " + problem;
        }
    }
    if (auto it = m.find("grid"); it != m.end() && it->is_array()) {
        if (it->size() != 2 || !(*it)[0].is_number_integer() || !(*it)[1].is_number_integer())
            return "\"grid\" is not [nTheta, nPhi]";
        const std::string problem = gridProblem((*it)[0].get<int>(), (*it)[1].get<int>());
        if (!problem.empty()) return "\"grid\": " + problem;
    }
    if (auto it = m.find("filterWidth"); it != m.end()) {
        if (!it->is_number() || !(it->get<double>() >= 0.0) ||
            it->get<double>() > limits::kMaxFilterWidth)
            return str("\"filterWidth\" ", it->dump(), " is not in [0, ", limits::kMaxFilterWidth, "]");
    }
    if (auto it = m.find("maxBounces"); it != m.end()) {
        if (!it->is_number_integer() || it->get<int64_t>() < 1 ||
            it->get<int64_t>() > limits::kMaxBounces)
            return str("\"maxBounces\" ", it->dump(), " is not in [1, ", limits::kMaxBounces, "]");
    }
    if (auto it = m.find("branch"); it != m.end()) {
        if (*it != "fresnel" && *it != "transmit")
            return str("\"branch\" ", it->dump(), " is not \"fresnel\" or \"transmit\"");
    }
    if (auto it = m.find("input"); it != m.end() && !it->is_string())
        return "\"input\" is not a string";
    return "";
}

// Checks that `part` is a scanline part of width x height with the channels (and types) given.
void checkPart(const Imf::Header& h, const char* name, int width, int height,
               const std::vector<Channel>& channels) {
    if (h.hasType() && h.type() != Imf::SCANLINEIMAGE)
        throw InputError(str("part \"", name, "\" is not a scanline image"));
    const Imath::Box2i& dw = h.dataWindow();
    if (dw.min.x != 0 || dw.min.y != 0 || dw.max.x != width - 1 || dw.max.y != height - 1)
        throw InputError(str("part \"", name, "\" has data window (", dw.min.x, ",", dw.min.y,
                             ")-(", dw.max.x, ",", dw.max.y, "), expected (0,0)-(", width - 1, ",",
                             height - 1, ")"));
    for (const Channel& c : channels) {
        const Imf::Channel* found = h.channels().findChannel(c.name);
        if (!found) throw InputError(str("part \"", name, "\" has no channel \"", c.name, "\""));
        if (found->type != c.type)
            throw InputError(str("part \"", name, "\" channel \"", c.name, "\" is ",
                                 pixelTypeName(found->type), ", expected ", pixelTypeName(c.type)));
    }
}

// What a version 2 file says its parts' checksums are, and the check against what was read.
class Verifier {
public:
    Verifier(const json& manifest, bool on) : on_(on) {
        if (!on_) return;
        auto it = manifest.find("checksums");
        if (it == manifest.end() || !it->is_object() || it->value("algorithm", "") != kChecksumAlgorithm ||
            !it->contains("parts") || !(*it)["parts"].is_object())
            throw InputError(str("manifest has no \"checksums\" of algorithm ", kChecksumAlgorithm));
        parts_ = (*it)["parts"];
    }
    bool on() const { return on_; }
    void check(const char* part, const std::string& actual) const {
        if (!on_) return;
        auto it = parts_.find(part);
        if (it == parts_.end() || !it->is_string())
            throw InputError(str("manifest has no checksum for part \"", part, "\""));
        if (it->get<std::string>() != actual)
            throw InputError(str("part \"", part, "\" is corrupt: its data do not match its checksum (",
                                 it->get<std::string>(), " recorded, ", actual, " read)"));
    }

private:
    bool on_;
    json parts_;
};

void readWhole(Imf::MultiPartInputFile& file, int part, Planes& planes, int height,
               const Verifier& verifier, const char* name) {
    Imf::InputPart in(file, part);
    in.setFrameBuffer(planes.frameBuffer(0));
    in.readPixels(0, height - 1);
    if (verifier.on()) verifier.check(name, checksumHex(planes.bytes().data(), planes.bytes().size()));
}

// The weights part into out[(k * N + i) * 4 + c], a band of rows at a time, dequantized to float.
// Verified, every row is read (the checksum covers the padding past the last sample too).
void readWeights(Imf::MultiPartInputFile& file, int part, const WeightsPart& shape, float* out,
                 const U8Params& u8, const Verifier& verifier) {
    const int K = shape.K;
    const size_t N = shape.N;
    const std::vector<Channel> channels = weightChannels(K, shape.precision);
    Imf::InputPart in(file, part);
    Checksum sum;
    for (int y0 = 0; y0 < shape.height && (verifier.on() || shape.map || size_t(y0) * shape.width < N);
         y0 += kChunkRows) {
        const int rows = std::min(kChunkRows, shape.height - y0);
        Planes chunk(shape.width, rows, channels);
        in.setFrameBuffer(chunk.frameBuffer(y0));
        in.readPixels(y0, y0 + rows - 1);
        sum.update(chunk.bytes().data(), chunk.bytes().size());
        for (size_t t = 0; t < size_t(shape.width) * rows; ++t) {
            const uint32_t i = sampleOfTexel(shape.map, size_t(y0) * shape.width + t, N);
            if (i == kNoSample) continue;
            for (int k = 0; k < K; ++k) {
                float* w = &out[(size_t(k) * N + i) * 4];
                if (shape.precision == Precision::U8) {
                    const uint32_t packed = chunk.u(t, k);
                    for (int c = 0; c < 4; ++c)
                        w[c] = dequantU8(u8.scale[k * 4 + c], u8.offset[k * 4 + c],
                                         (packed >> (8 * c)) & 0xffu);
                } else {
                    for (int c = 0; c < 4; ++c)
                        w[c] = shape.precision == Precision::F16 ? chunk.h(t, k * 4 + c)
                                                                 : chunk.f(t, k * 4 + c);
                }
            }
        }
    }
    verifier.check(kWeightsPart, sum.hex());
}

// The order of the manifest's "errorModel", checked against its coefficient count.
int readErrorOrder(const json& m) {
    const json& e = m[kErrorModelKey];
    if (!e.is_object()) throw InputError("manifest \"errorModel\" is not an object");
    const int order = manifestInt(e, "order");
    if (order < 0 || order > limits::kMaxErrorOrder)
        throw InputError(str("error model order ", order, " is not in [0, ", limits::kMaxErrorOrder, "]"));
    if (manifestInt(e, "coefficients") != shEvenCount(order))
        throw InputError(str("error model says ", manifestInt(e, "coefficients"), " coefficients, order ",
                             order, " has ", shEvenCount(order)));
    return order;
}

// The error part into errors[k * N + i], verified.
std::vector<float> readErrors(Imf::MultiPartInputFile& file, int part, size_t N, int Ke, int width,
                              int height, const uint32_t* map, const Verifier& verifier) {
    const std::vector<Channel> channels = errorChannels(Ke);
    checkPart(file.header(part), kErrorPart, width, height, channels);
    Planes planes(width, height, channels);
    readWhole(file, part, planes, height, verifier, kErrorPart);
    std::vector<float> errors(size_t(Ke) * N, 0.0f);
    for (size_t t = 0; t < size_t(width) * height; ++t) {
        const uint32_t i = sampleOfTexel(map, t, N);
        if (i == kNoSample) continue;
        for (int k = 0; k < Ke; ++k) errors[size_t(k) * N + i] = planes.f(t, k);
    }
    return errors;
}

// The manifest text of part 0, checked against its checksum and the copies in the other parts.
std::string manifestText(Imf::MultiPartInputFile& file, int version, bool verify) {
    const auto* text = file.header(0).findTypedAttribute<Imf::StringAttribute>(kManifestAttribute);
    if (!text) throw InputError("not a shrefract bake (no \"shrefract.manifest\" attribute)");
    if (version < 2 || !verify) return text->value();
    const auto* sum = file.header(0).findTypedAttribute<Imf::StringAttribute>(kManifestChecksumAttribute);
    if (!sum) throw InputError("the manifest has no checksum (\"shrefract.manifestChecksum\")");
    if (sum->value() != checksumHex(text->value()))
        throw InputError("the manifest is corrupt: it does not match its checksum");
    for (int p = 1; p < file.parts(); ++p) {
        const auto* copy = file.header(p).findTypedAttribute<Imf::StringAttribute>(kManifestAttribute);
        if (!copy || copy->value() != text->value())
            throw InputError(str("the manifest copy in part ", p, " differs from part 0's: the file is corrupt"));
    }
    return text->value();
}

// The unfolded mesh and the seam sources of a chart layout (sizes from the manifest's "layout").
template <class Find>
void readChartParts(Imf::MultiPartInputFile& file, Find find, const json& layout,
                    const Verifier& verifier, ChartAtlas& A) {
    auto count = [&](const char* key) {
        auto it = layout.find(key);
        if (it == layout.end() || !it->is_number_integer() || it->get<int64_t>() < 0 ||
            it->get<int64_t>() > (int64_t(1) << 31))
            throw InputError(str("manifest \"layout\" has no count \"", key, "\""));
        return size_t(it->get<int64_t>());
    };
    A.gutter = int(count("gutter"));
    A.chartCount = int(count("charts"));
    auto read = [&](const char* name, const std::vector<Channel>& ch, size_t n) {
        const int p = find(name);
        const auto [w, h] = neighbourListSize(n);
        checkPart(file.header(p), name, w, h, ch);
        Planes planes(w, h, ch);
        readWhole(file, p, planes, h, verifier, name);
        return planes;
    };
    const size_t V = count("vertices"), T = count("triangles"), S = count("seamSources");
    const Planes v = read(kChartVerticesPart, kChartVertexChannels, V);
    A.vertexPosition.resize(V);
    A.vertexNormal.resize(V);
    A.vertexUV.resize(V);
    A.vertexChart.resize(V);
    for (size_t i = 0; i < V; ++i) {
        A.vertexPosition[i] = {v.f(i, 0), v.f(i, 1), v.f(i, 2)};
        A.vertexNormal[i] = {v.f(i, 3), v.f(i, 4), v.f(i, 5)};
        A.vertexUV[i] = {v.f(i, 6), v.f(i, 7)};
        A.vertexChart[i] = v.u(i, 8);
    }
    const Planes t = read(kChartTrianglesPart, kChartTriangleChannels, T);
    A.triangles.resize(T);
    for (size_t i = 0; i < T; ++i) A.triangles[i] = {t.u(i, 0), t.u(i, 1), t.u(i, 2)};
    const Planes g = read(kSeamSourcesPart, kSeamSourceChannels, S);
    A.seam.resize(S);
    for (size_t i = 0; i < S; ++i) {
        A.seam[i].texel = g.u(i, 0);
        for (int k = 0; k < 4; ++k) {
            A.seam[i].sample[k] = g.u(i, 1 + k);
            A.seam[i].weight[k] = g.f(i, 5 + k);
        }
    }
}

// The manifest of the first part, the one that counts. Its version decides how it is verified,
// so it is parsed once unverified, then taken again through its checksum.
json openManifest(Imf::MultiPartInputFile& file, bool verify, int* version) {
    const auto* raw = file.header(0).findTypedAttribute<Imf::StringAttribute>(kManifestAttribute);
    if (!raw) throw InputError("not a shrefract bake (no \"shrefract.manifest\" attribute)");
    json m = json::parse(raw->value(), nullptr, /*allow_exceptions=*/false);
    if (m.is_discarded() || !m.is_object())
        throw InputError("not a shrefract bake (the manifest is not a JSON object)");
    if (!m.contains("format") || m["format"] != "shrefract")
        throw InputError("not a shrefract bake (manifest \"format\" is not \"shrefract\")");
    *version = manifestInt(m, "version");
    if (*version > kFormatVersion)
        throw InputError(str("format version ", *version, " is newer than this build reads (",
                             kFormatVersion, ")"));
    if (*version < 1) throw InputError(str("format version ", *version, " is invalid"));
    manifestText(file, *version, verify);
    return m;
}

// "slice 2 of 4" from a shard manifest's "shard" object, for messages.
std::string sliceName(const json& shard) {
    return str("slice ", shard.value("index", -1), " of ", shard.value("count", -1));
}

// `fileBytes`: the file's size, which bounds what its parts can decode to.
BakeData readParts(Imf::MultiPartInputFile& file, const ReadOptions& options, uint64_t fileBytes) {
    int version = 0;
    json m = openManifest(file, options.verify, &version);
    if (m.contains("shard"))
        throw InputError(str("is a shard (", sliceName(m["shard"]),
                             " of a bake), not a bake: merge a bake's shards with shrefract-merge"));
    std::vector<std::string> warnings;
    if (version < 2)
        warnings.push_back(str("format version ", version,
                               " carries no checksums: its data cannot be verified (re-bake to get "
                               "version ", kFormatVersion, ")"));
    const Verifier verifier(m, options.verify && version >= 2);
    BakeData d;
    SurfaceLayout& L = d.layout;
    json layoutInfo = json::object();
    if (version >= 2) {  // version 1 files are all joining layouts
        auto layout = m.find("layout");
        if (layout == m.end() || !layout->is_object() || !layout->contains("kind") ||
            !(*layout)["kind"].is_string())
            throw InputError("manifest has no \"layout\" kind");
        try {
            L.kind = parseLayoutKind((*layout)["kind"].get<std::string>());
        } catch (const InputError&) {
            throw InputError(str("unknown layout kind ", (*layout)["kind"].dump()));
        }
        layoutInfo = *layout;
    }

    d.order = manifestInt(m, "order");
    if (d.order < 0 || d.order > limits::kMaxOrder)
        throw InputError(str("SH order ", d.order, " is not in [0, ", limits::kMaxOrder, "]"));
    if (const std::string problem = manifestProblem(m); !problem.empty())
        throw InputError("manifest: " + problem);
    const int K = d.coefficientCount();
    if (manifestInt(m, "coefficients") != K)
        throw InputError(str("manifest says ", manifestInt(m, "coefficients"),
                             " coefficients, order ", d.order, " has ", K));
    if (!m.contains("precision") || !m["precision"].is_string())
        throw InputError("manifest has no \"precision\"");
    d.precision = parsePrecision(m["precision"].get<std::string>());

    const int N = manifestInt(m, "sampleCount");
    const std::vector<int> mu = manifestInts(m, "mu", 2), rho = manifestInts(m, "rho", 2),
                           block = manifestInts(m, "block", 3);
    L.muWidth = mu[0], L.muHeight = mu[1];
    L.rhoWidth = rho[0], L.rhoHeight = rho[1];
    L.blockWidth = block[0], L.blockHeight = block[1], L.blocksPerRow = block[2];
    L.triangleCount = manifestInt(m, "triangleCount");
    L.rate = manifestInt(m, "rate");
    const int nlWidth = manifestInt(m, "neighbourListWidth");
    const int nlLength = manifestInt(m, "neighbourListLength");
    if (L.muWidth < 1 || L.muHeight < 1 || L.rhoWidth < 1 || L.rhoHeight < 1 || nlWidth < 1)
        throw InputError(str("manifest sizes are invalid: mu ", L.muWidth, " x ", L.muHeight,
                             ", rho ", L.rhoWidth, " x ", L.rhoHeight, ", neighbour list width ",
                             nlWidth));
    if (N < 0 || int64_t(N) > int64_t(L.muWidth) * L.muHeight)
        throw InputError(
            str(N, " samples do not fit the ", L.muWidth, " x ", L.muHeight, " mu layout"));
    if (nlLength < 0) throw InputError(str("neighbour list length ", nlLength, " is negative"));
    for (int side : {L.muWidth, L.muHeight, L.rhoWidth, L.rhoHeight, nlWidth})
        if (side > limits::kMaxTextureSize)
            throw InputError(str("manifest sizes are invalid: a side of ", side, " texels is above ",
                                 limits::kMaxTextureSize));
    U8Params u8;
    if (d.precision == Precision::U8) {
        if (!m.contains("u8")) throw InputError("8-bit bake without \"u8\" scale and offset");
        u8.scale = manifestNumbers(m["u8"], "scale", size_t(K) * 4);
        u8.offset = manifestNumbers(m["u8"], "offset", size_t(K) * 4);
        d.u8Scale.assign(u8.scale.begin(), u8.scale.end());
        d.u8Offset.assign(u8.offset.begin(), u8.offset.end());
    }

    std::map<std::string, int> parts;
    for (int p = 0; p < file.parts(); ++p)
        if (file.header(p).hasName()) parts[file.header(p).name()] = p;
    auto find = [&](const char* name) {
        auto it = parts.find(name);
        if (it == parts.end()) throw InputError(str("missing part \"", name, "\""));
        return it->second;
    };
    const int pWeights = find(kWeightsPart), pSamples = find(kSamplesPart), pRho = find(kRhoPart),
              pNeighbours = find(kNeighboursPart), pList = find(kNeighbourListPart);
    const std::vector<Channel> wChannels = weightChannels(K, d.precision);
    checkPart(file.header(pWeights), kWeightsPart, L.muWidth, L.muHeight, wChannels);
    checkPart(file.header(pSamples), kSamplesPart, L.muWidth, L.muHeight, kSampleChannels);
    checkPart(file.header(pRho), kRhoPart, L.rhoWidth, L.rhoHeight, kRhoChannels);
    checkPart(file.header(pNeighbours), kNeighboursPart, L.muWidth, L.muHeight, kNeighbourChannels);
    const Imath::Box2i& listWindow = file.header(pList).dataWindow();
    const int nlHeight = listWindow.max.y - listWindow.min.y + 1;
    checkPart(file.header(pList), kNeighbourListPart, nlWidth, nlHeight, kNeighbourListChannels);
    if (int64_t(nlWidth) * nlHeight < nlLength)
        throw InputError(str("neighbour list of ", nlLength, " entries does not fit its ", nlWidth,
                             " x ", nlHeight, " part"));
    // zlib inflates at most ~1032:1, so the parts cannot hold more than ~1100 times the file's
    // bytes: sizes beyond that are corrupt, and are refused before anything is allocated.
    const uint64_t muTexels = uint64_t(L.muWidth) * uint64_t(L.muHeight);
    const uint64_t pixelBytes = muTexels * weightsTexelBytes(K, d.precision) + muTexels * (28 + 8) +
                                (m.contains(kErrorModelKey) ? muTexels * 4 * kMaxErrorTexelValues : 0) +
                                uint64_t(L.rhoWidth) * uint64_t(L.rhoHeight) * 16 +
                                uint64_t(nlWidth) * uint64_t(std::max(nlHeight, 0)) * 8;
    if (pixelBytes > 1100 * fileBytes + (1u << 20))
        throw InputError(str("truncated or corrupt: its parts would hold ", pixelBytes,
                             " bytes, more than a file of ", fileBytes, " bytes can"));

    // rho first: in a chart layout it says where each sample sits in the mu parts.
    Planes rhoPlanes(L.rhoWidth, L.rhoHeight, kRhoChannels);
    readWhole(file, pRho, rhoPlanes, L.rhoHeight, verifier, kRhoPart);
    L.rho.resize(size_t(L.rhoWidth) * L.rhoHeight);
    for (size_t t = 0; t < L.rho.size(); ++t)
        L.rho[t] = {rhoPlanes.u(t, 0), rhoPlanes.u(t, 1), rhoPlanes.u(t, 2), rhoPlanes.u(t, 3)};
    std::vector<uint32_t> texelMap;  // chart layouts: the sample at each mu texel
    if (L.isChartLayout()) {
        if (L.rhoWidth != L.muWidth || L.rhoHeight != L.muHeight)
            throw InputError(str("inconsistent bake: chart layout with rho ", L.rhoWidth, " x ",
                                 L.rhoHeight, " unlike its atlas ", L.muWidth, " x ", L.muHeight));
        texelMap.assign(L.rho.size(), kNoSample);
        L.atlas.sampleTexel.assign(size_t(N), kNoSample);
        for (size_t t = 0; t < L.rho.size(); ++t) {
            const RhoTexel& r = L.rho[t];
            if (r.kind == RhoTexel::Empty) continue;
            if (r.kind != RhoTexel::Sample || r.a >= uint32_t(N) || L.atlas.sampleTexel[r.a] != kNoSample)
                throw InputError(str("inconsistent bake: atlas texel (", t % size_t(L.muWidth), ", ",
                                     t / size_t(L.muWidth), ") is not one sample's own texel"));
            texelMap[t] = r.a;
            L.atlas.sampleTexel[r.a] = uint32_t(t);
        }
        for (int i = 0; i < N; ++i)
            if (L.atlas.sampleTexel[i] == kNoSample)
                throw InputError(str("inconsistent bake: sample ", i, " has no atlas texel"));
    }

    d.weights.assign(size_t(K) * N * 4, 0.0f);
    readWeights(file, pWeights,
                {nullptr, size_t(N), K, d.precision, L.muWidth, L.muHeight,
                 texelMap.empty() ? nullptr : texelMap.data()},
                d.weights.data(), u8, verifier);

    Planes samples(L.muWidth, L.muHeight, kSampleChannels);
    readWhole(file, pSamples, samples, L.muHeight, verifier, kSamplesPart);
    Planes neighbours(L.muWidth, L.muHeight, kNeighbourChannels);
    readWhole(file, pNeighbours, neighbours, L.muHeight, verifier, kNeighboursPart);
    L.position.resize(N);
    L.normal.resize(N);
    L.part.resize(N);
    L.neighbourOffset.resize(N);
    L.neighbourCount.resize(N);
    for (int i = 0; i < N; ++i) {
        const size_t t = L.isChartLayout() ? size_t(L.atlas.sampleTexel[i]) : size_t(i);
        L.position[i] = {samples.f(t, 0), samples.f(t, 1), samples.f(t, 2)};
        L.normal[i] = {samples.f(t, 3), samples.f(t, 4), samples.f(t, 5)};
        L.part[i] = samples.u(t, 6);
        L.neighbourOffset[i] = neighbours.u(t, 0);
        L.neighbourCount[i] = neighbours.u(t, 1);
    }

    Planes list(nlWidth, nlHeight, kNeighbourListChannels);
    readWhole(file, pList, list, nlHeight, verifier, kNeighbourListPart);
    L.neighbourIndex.resize(nlLength);
    L.neighbourWeight.resize(nlLength);
    for (int e = 0; e < nlLength; ++e) {
        L.neighbourIndex[e] = list.u(e, 0);
        L.neighbourWeight[e] = list.f(e, 1);
    }
    if (L.isChartLayout()) readChartParts(file, find, layoutInfo, verifier, L.atlas);
    if (version >= 3 && m.contains(kErrorModelKey)) {
        d.errorOrder = readErrorOrder(m);
        d.errors = readErrors(file, find(kErrorPart), size_t(N), d.errorCoefficientCount(), L.muWidth,
                              L.muHeight, texelMap.empty() ? nullptr : texelMap.data(), verifier);
    }

    const std::string problem = inconsistency(d);
    if (!problem.empty()) throw InputError("inconsistent bake: " + problem);
    if (auto media = m.find("media"); media != m.end() && !media->empty()) {
        for (int i = 0; i < N; ++i)
            if (L.part[i] >= media->size())
                throw InputError(str("inconsistent bake: sample ", i, " lies on part ", L.part[i],
                                     " but the manifest has ", media->size(), " media"));
    }
    d.manifest = std::move(m);
    d.warnings = std::move(warnings);
    return d;
}

ShardData readShardParts(Imf::MultiPartInputFile& file, bool weights) {
    int version = 0;
    json m = openManifest(file, true, &version);
    if (!m.contains("shard") || !m["shard"].is_object())
        throw InputError("is a bake, not a shard (its manifest has no \"shard\")");
    if (version < 2) throw InputError(str("shard of format version ", version, " (shards are 2+)"));
    const Verifier verifier(m, true);
    ShardData d;
    d.order = manifestInt(m, "order");
    if (d.order < 0 || d.order > 100) throw InputError(str("SH order ", d.order, " is absurd"));
    const int K = shEvenCount(d.order);
    if (manifestInt(m, "coefficients") != K)
        throw InputError(str("manifest says ", manifestInt(m, "coefficients"),
                             " coefficients, order ", d.order, " has ", K));
    if (m.value("precision", "") != "f32") throw InputError("shard weights are not f32");
    const int N = manifestInt(m, "sampleCount");
    const std::vector<int> size = manifestInts(m, "weightsSize", 2);
    if (N < 0 || size[0] < 1 || size[1] < 1 || int64_t(N) > int64_t(size[0]) * size[1])
        throw InputError(str(N, " samples do not fit the ", size[0], " x ", size[1], " weights part"));
    d.sampleCount = size_t(N);
    if (weights) {
        int part = -1;
        for (int p = 0; p < file.parts(); ++p)
            if (file.header(p).hasName() && file.header(p).name() == kWeightsPart) part = p;
        if (part < 0) throw InputError(str("missing part \"", kWeightsPart, "\""));
        checkPart(file.header(part), kWeightsPart, size[0], size[1], weightChannels(K, Precision::F32));
        d.weights.assign(size_t(K) * d.sampleCount * 4, 0.0f);
        readWeights(file, part, {nullptr, d.sampleCount, K, Precision::F32, size[0], size[1]},
                    d.weights.data(), U8Params{}, verifier);
        if (m.contains(kErrorModelKey)) {
            d.errorOrder = readErrorOrder(m);
            int errorPart = -1;
            for (int p = 0; p < file.parts(); ++p)
                if (file.header(p).hasName() && file.header(p).name() == kErrorPart) errorPart = p;
            if (errorPart < 0) throw InputError(str("missing part \"", kErrorPart, "\""));
            d.errors = readErrors(file, errorPart, d.sampleCount, shEvenCount(d.errorOrder), size[0],
                                  size[1], nullptr, verifier);
        }
    }
    d.manifest = std::move(m);
    return d;
}

// Opens `path` for one of the readers, turning every failure into an InputError naming it.
template <class Read>
auto readFile(const std::string& path, Read&& read) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (!std::filesystem::exists(status)) throw inputError(path, "file not found");
    if (std::filesystem::is_directory(status))
        throw inputError(path, "is a directory, not a bake file");
    if (!std::filesystem::is_regular_file(status))
        throw inputError(path, "is not a regular file (a FIFO or device?), not a bake file");

    checkExrHeaders(path);  // before OpenEXR allocates what a damaged header claims
    std::unique_ptr<Imf::MultiPartInputFile> file;
    try {
        file = std::make_unique<Imf::MultiPartInputFile>(path.c_str());
    } catch (const std::exception& e) {
        throw inputError(path, str("not an OpenEXR file: ", e.what()));
    }
    try {
        return read(*file, uint64_t(std::filesystem::file_size(path, ec)));
    } catch (const InputError& e) {
        throw inputError(path, e.what());
    } catch (const Iex::BaseExc& e) {
        throw inputError(path, str("truncated or corrupt: ", e.what()));
    } catch (const std::bad_alloc&) {
        throw inputError(path, "sizes too large to load");
    }
}

}  // namespace

void writeBake(const std::string& path, const BakeData& data) {
    // Everything that can be checked is checked before the temporary file exists.
    const std::string problem = inconsistency(data);
    if (!problem.empty()) throw std::invalid_argument("writeBake(" + path + "): " + problem);
    if (!data.manifest.is_null() && !data.manifest.is_object())
        throw std::invalid_argument("writeBake(" + path + "): the manifest is not a JSON object");
    const SurfaceLayout& L = data.layout;
    const U8Params u8 = data.precision == Precision::U8 ? fitU8(data) : U8Params{};
    const std::pair<int, int> nlSize = neighbourListSize(L.neighbourIndex.size());
    const int nlWidth = nlSize.first, nlHeight = nlSize.second;  // (lambdas below capture them)

    // The parts' pixels are staged first: their checksums go into the manifest, which every
    // part's header carries.
    Planes samples(L.muWidth, L.muHeight, kSampleChannels);
    Planes neighbours(L.muWidth, L.muHeight, kNeighbourChannels);
    for (int i = 0; i < L.sampleCount(); ++i) {
        const glm::ivec2 x = L.muTexel(i);
        const size_t t = size_t(x.y) * L.muWidth + x.x;
        for (int c = 0; c < 3; ++c) {
            samples.setF(t, c, L.position[i][c]);
            samples.setF(t, 3 + c, L.normal[i][c]);
        }
        samples.setU(t, 6, L.part[i]);
        neighbours.setU(t, 0, L.neighbourOffset[i]);
        neighbours.setU(t, 1, L.neighbourCount[i]);
    }
    const std::vector<uint32_t> texelMap = L.isChartLayout() ? texelSamples(L) : std::vector<uint32_t>{};
    Planes rho(L.rhoWidth, L.rhoHeight, kRhoChannels);
    for (size_t t = 0; t < L.rho.size(); ++t) {
        rho.setU(t, 0, L.rho[t].kind);
        rho.setU(t, 1, L.rho[t].a);
        rho.setU(t, 2, L.rho[t].b);
        rho.setU(t, 3, L.rho[t].c);
    }
    Planes list(nlWidth, nlHeight, kNeighbourListChannels);
    for (size_t e = 0; e < L.neighbourIndex.size(); ++e) {
        list.setU(e, 0, L.neighbourIndex[e]);
        list.setF(e, 1, L.neighbourWeight[e]);
    }
    auto sum = [](const Planes& p) { return checksumHex(p.bytes().data(), p.bytes().size()); };

    // Chart layouts: the unfolded mesh and the seam sources, as near-square lists.
    struct ListPart {
        const char* name;
        std::vector<Channel> channels;
        int width, height;
        Planes planes;
    };
    std::vector<ListPart> chartParts;
    if (L.isChartLayout()) {
        const ChartAtlas& A = L.atlas;
        auto add = [&](const char* name, const std::vector<Channel>& ch, size_t n) -> Planes& {
            const auto [w, h] = neighbourListSize(n);
            chartParts.push_back({name, ch, w, h, Planes(w, h, ch)});
            return chartParts.back().planes;
        };
        Planes& v = add(kChartVerticesPart, kChartVertexChannels, A.vertexPosition.size());
        for (size_t i = 0; i < A.vertexPosition.size(); ++i) {
            for (int c = 0; c < 3; ++c) {
                v.setF(i, c, A.vertexPosition[i][c]);
                v.setF(i, 3 + c, A.vertexNormal[i][c]);
            }
            v.setF(i, 6, A.vertexUV[i].x);
            v.setF(i, 7, A.vertexUV[i].y);
            v.setU(i, 8, A.vertexChart[i]);
        }
        Planes& t = add(kChartTrianglesPart, kChartTriangleChannels, A.triangles.size());
        for (size_t i = 0; i < A.triangles.size(); ++i)
            for (int c = 0; c < 3; ++c) t.setU(i, c, A.triangles[i][c]);
        Planes& g = add(kSeamSourcesPart, kSeamSourceChannels, A.seam.size());
        for (size_t i = 0; i < A.seam.size(); ++i) {
            g.setU(i, 0, A.seam[i].texel);
            for (int k = 0; k < 4; ++k) {
                g.setU(i, 1 + k, A.seam[i].sample[k]);
                g.setF(i, 5 + k, A.seam[i].weight[k]);
            }
        }
    }

    const int Ke = data.errorCoefficientCount();
    std::unique_ptr<Planes> errors;
    if (Ke > 0)
        errors = std::make_unique<Planes>(errorPlanes(data.errors.data(), L.position.size(), Ke, L.muWidth,
                                                      L.muHeight, texelMap.empty() ? nullptr : texelMap.data()));

    json m = data.manifest.is_null() ? json::object() : data.manifest;
    m["format"] = "shrefract";
    m["version"] = kFormatVersion;
    m["order"] = data.order;
    m["coefficients"] = data.coefficientCount();
    m["precision"] = ToString(data.precision);
    m["sampleCount"] = L.sampleCount();
    m["mu"] = {L.muWidth, L.muHeight};
    m["rho"] = {L.rhoWidth, L.rhoHeight};
    m["block"] = {L.blockWidth, L.blockHeight, L.blocksPerRow};
    m["triangleCount"] = L.triangleCount;
    m["rate"] = L.rate;
    m["neighbourListWidth"] = nlWidth;
    m["neighbourListLength"] = L.neighbourIndex.size();
    // "layout": the kind and, for charts, the part sizes are the writer's; other keys the bake
    // tool put there stay (descriptive).
    json layout = m.contains("layout") && m["layout"].is_object() ? m["layout"] : json::object();
    layout["kind"] = ToString(L.kind);
    for (const char* key : {"gutter", "charts", "vertices", "triangles", "seamSources"}) layout.erase(key);
    if (L.isChartLayout()) {
        const ChartAtlas& A = L.atlas;
        layout["gutter"] = A.gutter;
        layout["charts"] = A.chartCount;
        layout["vertices"] = A.vertexPosition.size();
        layout["triangles"] = A.triangles.size();
        layout["seamSources"] = A.seam.size();
    }
    m["layout"] = layout;
    if (data.precision == Precision::U8)
        m["u8"] = {{"scale", u8.scale}, {"offset", u8.offset}};
    else
        m.erase("u8");
    if (errors)
        m[kErrorModelKey] = errorModelInfo(data.errorOrder);
    else
        m.erase(kErrorModelKey);
    m["checksums"] = {{"algorithm", kChecksumAlgorithm},
                      {"parts",
                       {{kWeightsPart, weightsChecksum(weightsPart(data, texelMap), u8)},
                        {kSamplesPart, sum(samples)},
                        {kRhoPart, sum(rho)},
                        {kNeighboursPart, sum(neighbours)},
                        {kNeighbourListPart, sum(list)}}}};
    for (const ListPart& p : chartParts) m["checksums"]["parts"][p.name] = sum(p.planes);
    if (errors) m["checksums"]["parts"][kErrorPart] = sum(*errors);
    std::string text;
    try {
        text = m.dump();
    } catch (const json::exception& e) {
        throw std::invalid_argument("writeBake(" + path + "): manifest: " + e.what());
    }

    const Imath::Box2i display({0, 0}, {L.muWidth - 1, L.muHeight - 1});
    std::vector<Imf::Header> headers = {
        partHeader(kWeightsPart, L.muWidth, L.muHeight, display, text),
        partHeader(kSamplesPart, L.muWidth, L.muHeight, display, text),
        partHeader(kRhoPart, L.rhoWidth, L.rhoHeight, display, text),
        partHeader(kNeighboursPart, L.muWidth, L.muHeight, display, text),
        partHeader(kNeighbourListPart, nlWidth, nlHeight, display, text)};
    addChannels(headers[0], weightChannels(data.coefficientCount(), data.precision));
    addChannels(headers[1], kSampleChannels);
    addChannels(headers[2], kRhoChannels);
    addChannels(headers[3], kNeighbourChannels);
    addChannels(headers[4], kNeighbourListChannels);
    for (const ListPart& p : chartParts) {
        headers.push_back(partHeader(p.name, p.width, p.height, display, text));
        addChannels(headers.back(), p.channels);
    }
    if (errors) {
        headers.push_back(partHeader(kErrorPart, L.muWidth, L.muHeight, display, text));
        addChannels(headers.back(), errorChannels(Ke));
    }

    writeAtomically(path, [&](const std::string& staged) {
        writeExrFile(staged, [&](Imf::OStream& stream) {
            Imf::MultiPartOutputFile file(stream, headers.data(), int(headers.size()));
            writeWeights(file, 0, weightsPart(data, texelMap), u8);
            writeWhole(file, 1, samples, L.muHeight);
            writeWhole(file, 2, rho, L.rhoHeight);
            writeWhole(file, 3, neighbours, L.muHeight);
            writeWhole(file, 4, list, nlHeight);
            for (size_t p = 0; p < chartParts.size(); ++p)
                writeWhole(file, int(5 + p), chartParts[p].planes, chartParts[p].height);
            if (errors) writeWhole(file, int(5 + chartParts.size()), *errors, L.muHeight);
        });
    });
}

BakeData readBake(const std::string& path, const ReadOptions& options) {
    return readFile(path, [&](Imf::MultiPartInputFile& file, uint64_t bytes) {
        return readParts(file, options, bytes);
    });
}

void writeShard(const std::string& path, const ShardData& shard) {
    const int K = shEvenCount(shard.order);
    if (shard.order < 0 || shard.weights.size() != size_t(K) * shard.sampleCount * 4)
        throw std::invalid_argument(str("writeShard(", path, "): ", shard.weights.size(),
                                        " weights, expected ", K, " coefficients x ",
                                        shard.sampleCount, " samples x 4"));
    if (!shard.manifest.is_object() || !shard.manifest.contains("shard") ||
        !shard.manifest["shard"].is_object())
        throw std::invalid_argument("writeShard(" + path + "): the manifest has no \"shard\" object");
    const int Ke = shard.errorOrder < 0 ? 0 : shEvenCount(shard.errorOrder);
    if (shard.errorOrder > limits::kMaxErrorOrder || shard.errors.size() != size_t(Ke) * shard.sampleCount)
        throw std::invalid_argument(str("writeShard(", path, "): ", shard.errors.size(),
                                        " error model values, expected ", Ke, " x ", shard.sampleCount));
    const auto [width, height] = neighbourListSize(shard.sampleCount);
    const WeightsPart part{shard.weights.data(), shard.sampleCount, K, Precision::F32, width, height};
    std::unique_ptr<Planes> errors;
    if (Ke > 0) errors = std::make_unique<Planes>(errorPlanes(shard.errors.data(), shard.sampleCount, Ke, width, height, nullptr));
    json m = shard.manifest;
    m["format"] = "shrefract";
    m["version"] = kFormatVersion;
    m["order"] = shard.order;
    m["coefficients"] = K;
    m["precision"] = "f32";
    m["sampleCount"] = shard.sampleCount;
    m["weightsSize"] = {width, height};
    m["checksums"] = {{"algorithm", kChecksumAlgorithm},
                      {"parts", {{kWeightsPart, weightsChecksum(part, U8Params{})}}}};
    if (errors) {
        m[kErrorModelKey] = errorModelInfo(shard.errorOrder);
        m["checksums"]["parts"][kErrorPart] = checksumHex(errors->bytes().data(), errors->bytes().size());
    } else {
        m.erase(kErrorModelKey);
    }
    std::string text;
    try {
        text = m.dump();
    } catch (const json::exception& e) {
        throw std::invalid_argument("writeShard(" + path + "): manifest: " + e.what());
    }
    // Float weights hardly compress (docs/format.md "Size"): shards are stored uncompressed.
    std::vector<Imf::Header> headers = {partHeader(kWeightsPart, width, height,
                                                   Imath::Box2i({0, 0}, {width - 1, height - 1}),
                                                   text, Imf::NO_COMPRESSION)};
    addChannels(headers[0], weightChannels(K, Precision::F32));
    if (errors) {
        headers.push_back(partHeader(kErrorPart, width, height, Imath::Box2i({0, 0}, {width - 1, height - 1}),
                                     text, Imf::NO_COMPRESSION));
        addChannels(headers.back(), errorChannels(Ke));
    }
    writeAtomically(path, [&](const std::string& staged) {
        writeExrFile(staged, [&](Imf::OStream& stream) {
            Imf::MultiPartOutputFile file(stream, headers.data(), int(headers.size()));
            writeWeights(file, 0, part, U8Params{});
            if (errors) writeWhole(file, 1, *errors, height);
        });
    });
}

ShardData readShard(const std::string& path, bool weights) {
    return readFile(path, [&](Imf::MultiPartInputFile& file, uint64_t) { return readShardParts(file, weights); });
}

}  // namespace shrefract
