// The JSON manifest every part of a bake or shard file carries: opened and checked against its
// checksum and its copies, its typed values, the parts' checksums it records (Verifier) and the
// error model it describes.
#include <ImfStringAttribute.h>

#include <cmath>

#include "common/checksum.h"
#include "common/format_internal.h"
#include "common/limits.h"
#include "common/sh.h"

namespace shrefract::format_internal {

namespace {

bool fitsInt(const json& x) {
    if (!x.is_number_integer()) return false;
    if (x.is_number_unsigned()) return x.get<uint64_t>() <= uint64_t(INT32_MAX);
    return x.get<int64_t>() >= INT32_MIN && x.get<int64_t>() <= INT32_MAX;
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

}  // namespace

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

Verifier::Verifier(const json& manifest, bool on) : on_(on) {
    if (!on_) return;
    auto it = manifest.find("checksums");
    if (it == manifest.end() || !it->is_object() || it->value("algorithm", "") != kChecksumAlgorithm ||
        !it->contains("parts") || !(*it)["parts"].is_object())
        throw InputError(str("manifest has no \"checksums\" of algorithm ", kChecksumAlgorithm));
    parts_ = (*it)["parts"];
}

void Verifier::check(const char* part, const std::string& actual) const {
    if (!on_) return;
    auto it = parts_.find(part);
    if (it == parts_.end() || !it->is_string())
        throw InputError(str("manifest has no checksum for part \"", part, "\""));
    if (it->get<std::string>() != actual)
        throw InputError(str("part \"", part, "\" is corrupt: its data do not match its checksum (",
                             it->get<std::string>(), " recorded, ", actual, " read)"));
}

// The manifest's "errorModel" object: what the part holds and how to read it.
json errorModelInfo(int order) {
    return {{"order", order},
            {"coefficients", shEvenCount(order)},
            {"quantity", "ln(angle + offset), the angle in radians between the fitted and the traced exit"},
            {"offset", kErrorOffset},
            {"unit", "radians"}};
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

void writeBasis(json& m, Basis basis, int order, const DirectionGrid& grid) {
    m["order"] = order;
    m["coefficients"] = basisCoefficients(basis, order, grid);
    if (basis == Basis::Grid) {
        m["basis"] = nameOf(basis);
        m["grid"] = {grid.nTheta, grid.nPhi};  // the coefficients' layout, so the reader's to check
    } else {
        m.erase("basis");  // an SH bake's "grid" is the caller's description of its tracing
    }
}

int readBasis(const json& m, Basis* basis, int* order, DirectionGrid* grid) {
    *basis = Basis::Sh;
    if (m.contains("basis")) {
        if (!m["basis"].is_string()) throw InputError("manifest \"basis\" is not a string");
        *basis = parseInput<Basis>(m["basis"].get<std::string>());
    }
    *order = manifestInt(m, "order");
    if (*order < 0 || *order > limits::kMaxOrder)
        throw InputError(str("SH order ", *order, " is not in [0, ", limits::kMaxOrder, "]"));
    if (*basis == Basis::Grid && *order != 0)
        throw InputError(str("a grid-basis bake has SH order 0, not ", *order));
    const auto g = m.find("grid");
    const bool gridArray = g != m.end() && g->is_array() && g->size() == 2 && (*g)[0].is_number_integer() &&
                           (*g)[1].is_number_integer();
    if (*basis == Basis::Grid || gridArray) {
        const std::vector<int> g = manifestInts(m, "grid", 2);
        if (const std::string problem = gridProblem(g[0], g[1]); !problem.empty())
            throw InputError("manifest \"grid\": " + problem);
        grid->nTheta = g[0], grid->nPhi = g[1];
    }
    if (*basis == Basis::Grid && grid->count() > limits::kMaxGridBasis)
        throw InputError(str("a grid-basis bake of ", grid->ToString(), " stores ", grid->count(),
                             " coefficients per sample, more than ", limits::kMaxGridBasis));
    const int K = basisCoefficients(*basis, *order, *grid);
    if (manifestInt(m, "coefficients") != K)
        throw InputError(str("manifest says ", manifestInt(m, "coefficients"), " coefficients, ",
                             *basis == Basis::Grid ? "grid " + grid->ToString() : str("order ", *order),
                             " has ", K));
    return K;
}

}  // namespace shrefract::format_internal

namespace shrefract {

using nlohmann::json;

namespace {
const json* firstMedium(const BakeData& d) {
    const json& m = d.manifest;
    if (!m.is_object() || !m.contains("media") || !m["media"].is_array() || m["media"].empty())
        return nullptr;
    return &m["media"][0];
}
}  // namespace

float frontIor(const BakeData& d) {
    const json* m = firstMedium(d);
    if (m && m->contains("ior") && (*m)["ior"].is_number()) return (*m)["ior"].get<float>();
    return 1.5f;
}

glm::vec3 frontAbsorption(const BakeData& d) {
    const json* m = firstMedium(d);
    if (m && m->contains("absorption") && (*m)["absorption"].is_array() &&
        (*m)["absorption"].size() == 3)
        return {(*m)["absorption"][0].get<float>(), (*m)["absorption"][1].get<float>(),
                (*m)["absorption"][2].get<float>()};
    return glm::vec3(0.0f);
}

}  // namespace shrefract
