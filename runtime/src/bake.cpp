#include "common/bakefile.h"
#include "common/error.h"
#include "shrefract/runtime.h"

namespace shrefract {

Bake loadBake(const std::string& path, bool verify) {
    ReadOptions options;
    options.verify = verify;
    return makeBake(readBake(path, options));
}

Bake makeBake(BakeData data) {
    Bake b;
    b.data_ = std::make_shared<const BakeData>(std::move(data));
    return b;
}

const BakeData& Bake::data() const {
    SHREFRACT_CHECK(data_ != nullptr);
    return *data_;
}
int Bake::order() const { return data().order; }
const std::vector<std::string>& Bake::warnings() const { return data().warnings; }

std::vector<MapVertex> Bake::refractionMapMesh() const {
    // The layout's drawn mesh (common/bakefile.h drawCorners): joining, each triangle's corner
    // samples (0,0), (r,0), (0,r) at their rho texel centres (docs/format.md "rho"); charts, the
    // unfolded mesh at its atlas UVs.
    std::vector<MapVertex> out;
    for (const DrawCorner& c : drawCorners(data().layout)) out.push_back({c.position, c.normal, c.uv});
    return out;
}
int Bake::sampleCount() const { return data().layout.sampleCount(); }
int Bake::triangleCount() const { return data().layout.triangleCount; }
std::string Bake::layout() const { return ToString(data().layout.kind); }

// The first medium of the manifest is the object's (docs/format.md "media").
static const nlohmann::json* firstMedium(const BakeData& d) {
    const auto& m = d.manifest;
    if (!m.is_object() || !m.contains("media") || !m["media"].is_array() || m["media"].empty())
        return nullptr;
    return &m["media"][0];
}

float Bake::ior() const {
    const nlohmann::json* m = firstMedium(data());
    if (m && m->contains("ior") && (*m)["ior"].is_number()) return (*m)["ior"].get<float>();
    return 1.5f;
}

glm::vec3 Bake::absorption() const {
    const nlohmann::json* m = firstMedium(data());
    if (m && m->contains("absorption") && (*m)["absorption"].is_array() &&
        (*m)["absorption"].size() == 3)
        return {(*m)["absorption"][0].get<float>(), (*m)["absorption"][1].get<float>(),
                (*m)["absorption"][2].get<float>()};
    return glm::vec3(0.0f);
}

}  // namespace shrefract
