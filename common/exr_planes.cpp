// The staging of a part's pixels (Planes, common/format_internal.h): the channels of every part
// of a bake or shard file, the part headers, and whole parts written, read and checked. What the
// parts hold is in common/format_internal.h and docs/format.md.
#include <ImfChannelList.h>
#include <ImfInputPart.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfStringAttribute.h>

#include <cmath>
#include <cstdio>

#include "common/checksum.h"
#include "common/format_internal.h"

namespace shrefract::format_internal {

namespace {

std::string weightChannel(int k, const char* suffix) {
    char name[32];
    std::snprintf(name, sizeof name, "w%03d.%s", k, suffix);
    return name;
}

size_t pixelSize(Imf::PixelType t) { return t == Imf::HALF ? 2 : 4; }
const char* pixelTypeName(Imf::PixelType t) {
    return t == Imf::UINT    ? "UINT"
           : t == Imf::HALF  ? "HALF"
           : t == Imf::FLOAT ? "FLOAT"
                             : "unknown";
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Staging.

Planes::Planes(int width, int rows, std::vector<Channel> channels)
    : width_(width), rows_(rows), channels_(std::move(channels)) {
    for (const Channel& c : channels_) {
        offset_.push_back(stride_);
        stride_ += pixelSize(c.type);
    }
    bytes_.assign(size_t(width_) * rows_ * stride_, 0);
}

Imf::FrameBuffer Planes::frameBuffer(int y0) {
    const size_t yStride = stride_ * width_;
    Imf::FrameBuffer fb;
    for (size_t c = 0; c < channels_.size(); ++c) {
        char* base = reinterpret_cast<char*>(bytes_.data()) + offset_[c] -
                     static_cast<std::ptrdiff_t>(y0) * static_cast<std::ptrdiff_t>(yStride);
        fb.insert(channels_[c].name, Imf::Slice(channels_[c].type, base, stride_, yStride));
    }
    return fb;
}

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

// Near-square: width ceil(sqrt(E)), at least one texel.
std::pair<int, int> neighbourListSize(size_t E) {
    if (E == 0) return {1, 1};
    int w = static_cast<int>(std::ceil(std::sqrt(double(E))));
    while (size_t(w) * size_t(w) < E) ++w;
    const int h = static_cast<int>((E + size_t(w) - 1) / size_t(w));
    return {w, h};
}

// ---------------------------------------------------------------------------------------------
// Whole parts.

Imf::Header partHeader(const char* name, int width, int height, const Imath::Box2i& display,
                       const std::string& manifest, Imf::Compression compression) {
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

void readWhole(Imf::MultiPartInputFile& file, int part, Planes& planes, int height,
               const Verifier& verifier, const char* name) {
    Imf::InputPart in(file, part);
    in.setFrameBuffer(planes.frameBuffer(0));
    in.readPixels(0, height - 1);
    if (verifier.on()) verifier.check(name, checksumHex(planes.bytes().data(), planes.bytes().size()));
}

}  // namespace shrefract::format_internal
