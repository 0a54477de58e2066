// Shards: one slice of a bake's samples, f32 weights (and error model) only, stored uncompressed;
// shrefract-merge turns a bake's shards into its bake file (docs/format.md "Shards").
#include <ImfMultiPartOutputFile.h>

#include <memory>
#include <stdexcept>

#include "common/checksum.h"
#include "common/exr_output.h"
#include "common/format_internal.h"
#include "common/limits.h"
#include "common/output.h"
#include "common/sh.h"

namespace shrefract {
namespace {

using namespace format_internal;

ShardData readShardParts(Imf::MultiPartInputFile& file, bool weights) {
    int version = 0;
    json m = openManifest(file, true, &version);
    if (!m.contains("shard") || !m["shard"].is_object())
        throw InputError("is a bake, not a shard (its manifest has no \"shard\")");
    if (version < 2) throw InputError(str("shard of format version ", version, " (shards are 2+)"));
    const Verifier verifier(m, true);
    ShardData d;
    const int K = readBasis(m, &d.basis, &d.order, &d.grid);
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

}  // namespace

void writeShard(const std::string& path, const ShardData& shard) {
    const int K = basisCoefficients(shard.basis, shard.order, shard.grid);
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
    // Plain variables, not a structured binding: the lambdas below capture them (C++17).
    const auto listSize = neighbourListSize(shard.sampleCount);
    const int width = listSize.first, height = listSize.second;
    const WeightsPart part{shard.weights.data(), shard.sampleCount, K, Precision::F32, width, height};
    std::unique_ptr<Planes> errors;
    if (Ke > 0) errors = std::make_unique<Planes>(errorPlanes(shard.errors.data(), shard.sampleCount, Ke, width, height, nullptr));
    json m = shard.manifest;
    m["format"] = "shrefract";
    m["version"] = kFormatVersion;
    writeBasis(m, shard.basis, shard.order, shard.grid);
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
