// readBake: NAME.shrefract.exr into a BakeData, every part checked against the manifest, its
// checksum and the format's invariants before anything is trusted (docs/format.md).
#include <algorithm>
#include <map>

#include "common/format_internal.h"
#include "common/limits.h"
#include "common/sh.h"

namespace shrefract {
namespace {

using namespace format_internal;

const uint64_t kMaxErrorTexelValues = uint64_t(shEvenCount(limits::kMaxErrorOrder));

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
        L.kind = parseInput<LayoutKind>((*layout)["kind"].get<std::string>());
        layoutInfo = *layout;
    }

    if (const std::string problem = manifestProblem(m); !problem.empty())
        throw InputError("manifest: " + problem);
    const int K = readBasis(m, &d.basis, &d.order, &d.grid);
    if (!m.contains("precision") || !m["precision"].is_string())
        throw InputError("manifest has no \"precision\"");
    d.precision = parseInput<Precision>(m["precision"].get<std::string>());

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

}  // namespace

uint64_t weightsTexelBytes(int K, Precision p) {
    return uint64_t(K) * (p == Precision::U8 ? 4 : p == Precision::F16 ? 8 : 16);
}

BakeData readBake(const std::string& path, const ReadOptions& options) {
    return readFile(path, [&](Imf::MultiPartInputFile& file, uint64_t bytes) {
        return readParts(file, options, bytes);
    });
}

}  // namespace shrefract
