// writeBake: a BakeData into NAME.shrefract.exr, checked first, staged part by part, written to a
// temporary file and renamed (docs/format.md).
#include <ImfMultiPartOutputFile.h>

#include <memory>
#include <stdexcept>

#include "common/checksum.h"
#include "common/exr_output.h"
#include "common/format_internal.h"
#include "common/output.h"

namespace shrefract {
namespace {

using namespace format_internal;

// Which sample each mu texel holds (kNoSample: none), for chart layouts, where sample i sits at
// its atlas texel; joining layouts address sample i = texel index directly.
std::vector<uint32_t> texelSamples(const SurfaceLayout& L) {
    std::vector<uint32_t> map(size_t(L.muWidth) * L.muHeight, kNoSample);
    for (size_t i = 0; i < L.atlas.sampleTexel.size(); ++i) map[L.atlas.sampleTexel[i]] = uint32_t(i);
    return map;
}

WeightsPart weightsPart(const BakeData& d, const std::vector<uint32_t>& map) {
    return {d.weights.data(), d.layout.position.size(), d.coefficientCount(), d.precision,
            d.layout.muWidth, d.layout.muHeight, map.empty() ? nullptr : map.data()};
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
    writeBasis(m, data.basis, data.order, data.grid);
    m["precision"] = nameOf(data.precision);
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
    layout["kind"] = nameOf(L.kind);
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

}  // namespace shrefract
