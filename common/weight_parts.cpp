// The per-sample coefficient parts of a bake or shard file: the weights (f32, f16 or 8-bit codes,
// staged a band of rows at a time) and the error model, each sample at its texel.
#include <ImfInputPart.h>
#include <ImfOutputPart.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/checksum.h"
#include "common/format_internal.h"
#include "common/sh.h"

namespace shrefract {

int basisCoefficients(Basis basis, int order, const DirectionGrid& grid) {
    return basis == Basis::Grid ? grid.count() : shEvenCount(order);
}
int BakeData::coefficientCount() const { return basisCoefficients(basis, order, grid); }
std::string BakeData::modelName() const {
    return basis == Basis::Grid ? "grid basis " + grid.ToString() : "order " + std::to_string(order);
}
int BakeData::errorCoefficientCount() const { return errorOrder < 0 ? 0 : shEvenCount(errorOrder); }

namespace format_internal {
namespace {

// Rows staged per writePixels/readPixels call for the weights part (a ZIP block is 16 lines), so
// that the weights are never duplicated in memory at full size.
constexpr int kChunkRows = 16;

// The sample at texel `texel` (kNoSample: none): `map` for chart layouts (texelSamples), else
// the texel index itself while below the sample count.
uint32_t sampleOfTexel(const uint32_t* map, size_t texel, size_t N) {
    if (map) return map[texel];
    return texel < N ? uint32_t(texel) : kNoSample;
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

}  // namespace

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

}  // namespace format_internal
}  // namespace shrefract
