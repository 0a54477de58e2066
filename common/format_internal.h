// What the files behind common/bakefile.h share, not part of its API: the part and manifest
// names, the staging of a part's channels (exr_planes.cpp), the 8-bit weights (quantize.cpp),
// the weights and error model parts (weight_parts.cpp), the manifest (bake_manifest.cpp) and the
// consistency checks (bake_validate.cpp). Readers and writers: bake_read.cpp, bake_write.cpp,
// shard_io.cpp.
//
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
#pragma once

#include <Iex.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfMultiPartInputFile.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfPixelType.h>
#include <half.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <new>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "common/bakefile.h"
#include "common/error.h"
#include "common/exr_input.h"

namespace shrefract::format_internal {

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
constexpr uint32_t kNoSample = UINT32_MAX;
constexpr const char* kWeightSuffix[4] = {"x", "y", "z", "len"};

// ---------------------------------------------------------------------------------------------
// Staging: the channels of one part (or of a band of rows of it), interleaved per texel
// (exr_planes.cpp).

struct Channel {
    std::string name;
    Imf::PixelType type;
};

class Planes {
public:
    Planes(int width, int rows, std::vector<Channel> channels);
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
    Imf::FrameBuffer frameBuffer(int y0);
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

std::vector<Channel> weightChannels(int K, Precision p);
// The error model's channels: e000, e001, ... one FLOAT per coefficient.
std::vector<Channel> errorChannels(int Ke);
extern const std::vector<Channel> kSampleChannels, kRhoChannels, kNeighbourChannels,
    kNeighbourListChannels, kChartVertexChannels, kChartTriangleChannels, kSeamSourceChannels;

// The size of a near-square list part of E entries: width ceil(sqrt(E)), at least one texel.
std::pair<int, int> neighbourListSize(size_t E);

Imf::Header partHeader(const char* name, int width, int height, const Imath::Box2i& display,
                       const std::string& manifest,
                       Imf::Compression compression = Imf::ZIP_COMPRESSION);
void addChannels(Imf::Header& h, const std::vector<Channel>& channels);
void writeWhole(Imf::MultiPartOutputFile& file, int part, Planes& planes, int height);
// Checks that `part` is a scanline part of width x height with the channels (and types) given.
void checkPart(const Imf::Header& h, const char* name, int width, int height,
               const std::vector<Channel>& channels);

// ---------------------------------------------------------------------------------------------
// The manifest (bake_manifest.cpp).

int manifestInt(const json& m, const char* key);
std::vector<int> manifestInts(const json& m, const char* key, size_t n);
std::vector<double> manifestNumbers(const json& m, const char* key, size_t n);
// The manifest of the first part, the one that counts. Its version decides how it is verified,
// so it is parsed once unverified, then taken again through its checksum.
json openManifest(Imf::MultiPartInputFile& file, bool verify, int* version);
// The manifest's "errorModel" object: what the part holds and how to read it.
json errorModelInfo(int order);
// The order of the manifest's "errorModel", checked against its coefficient count.
int readErrorOrder(const json& m);
// The coefficients' basis in a manifest: "order", "coefficients" and, for the grid basis only,
// "basis": "grid" and "grid" (a file without "basis" is SH, as every file before version 4).
void writeBasis(json& m, Basis basis, int order, const DirectionGrid& grid);
// Reads them back, checks "coefficients" against the basis and returns that count. The grid is
// required by the grid basis; an SH file without one keeps `*grid` as it is.
int readBasis(const json& m, Basis* basis, int* order, DirectionGrid* grid);

// What a version 2 file says its parts' checksums are, and the check against what was read.
class Verifier {
public:
    Verifier(const json& manifest, bool on);
    bool on() const { return on_; }
    void check(const char* part, const std::string& actual) const;

private:
    bool on_;
    json parts_;
};

void readWhole(Imf::MultiPartInputFile& file, int part, Planes& planes, int height,
               const Verifier& verifier, const char* name);

// ---------------------------------------------------------------------------------------------
// 8-bit weights (quantize.cpp): value = scale * code + offset, per coefficient k and channel c.

struct U8Params {
    std::vector<double> scale, offset;  // [k * 4 + c]
};

float dequantU8(double scale, double offset, uint32_t code);
uint32_t quantU8(float v, double scale, double offset);
U8Params fitU8(const BakeData& d);

// ---------------------------------------------------------------------------------------------
// The weights and error model parts (weight_parts.cpp).

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

// The checksum of the whole weights part, chunk by chunk as it will be written.
std::string weightsChecksum(const WeightsPart& d, const U8Params& u8);
void writeWeights(Imf::MultiPartOutputFile& file, int part, const WeightsPart& d,
                  const U8Params& u8);
// The weights part into out[(k * N + i) * 4 + c], a band of rows at a time, dequantized to float.
// Verified, every row is read (the checksum covers the padding past the last sample too).
void readWeights(Imf::MultiPartInputFile& file, int part, const WeightsPart& shape, float* out,
                 const U8Params& u8, const Verifier& verifier);
// The error model's part: errors[k * N + i] at sample i's texel (`map` as for the weights).
Planes errorPlanes(const float* errors, size_t N, int Ke, int width, int height,
                   const uint32_t* map);
// The error part into errors[k * N + i], verified.
std::vector<float> readErrors(Imf::MultiPartInputFile& file, int part, size_t N, int Ke, int width,
                              int height, const uint32_t* map, const Verifier& verifier);

// ---------------------------------------------------------------------------------------------
// Consistency (bake_validate.cpp).

// Consistency of a BakeData, shared by writer (a caller bug: std::invalid_argument) and reader
// (a bad file: InputError). Returns what is wrong, or "" when consistent.
std::string inconsistency(const BakeData& d);
// The manifest's descriptive keys that tools act on, checked as the bake checks its options.
// Returns what is wrong, or "".
std::string manifestProblem(const json& m);

// ---------------------------------------------------------------------------------------------

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

}  // namespace shrefract::format_internal
