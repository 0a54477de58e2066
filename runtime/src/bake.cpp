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
    // Triangle t's corners are its grid samples (0,0), (r,0), (0,r); their uv the rho texel
    // centres (docs/format.md "rho").
    const SurfaceLayout& L = data().layout;
    const int r = L.rate;
    std::vector<MapVertex> out;
    out.reserve(static_cast<size_t>(L.triangleCount) * 3);
    for (int t = 0; t < L.triangleCount; ++t)
        for (glm::ivec2 c : {glm::ivec2(0, 0), glm::ivec2(r, 0), glm::ivec2(0, r)}) {
            const uint32_t s = L.sampleAt(t, c.x, c.y);
            const glm::ivec2 texel = L.rhoTexel(t, c.x, c.y);
            out.push_back({L.position[s], L.normal[s],
                           glm::vec2((texel.x + 0.5f) / L.rhoWidth, (texel.y + 0.5f) / L.rhoHeight)});
        }
    return out;
}
int Bake::sampleCount() const { return data().layout.sampleCount(); }
int Bake::triangleCount() const { return data().layout.triangleCount; }

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
