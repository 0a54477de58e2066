#include "bake_data.h"
#include "common/error.h"

namespace shrefract {

Bake loadBake(const std::string& path, bool verify) {
    ReadOptions options;
    options.verify = verify;
    return makeBake(readBake(path, options));
}

Bake makeBake(BakeData data) { return Bake(std::make_shared<const Bake::Impl>(Bake::Impl{std::move(data)})); }

Bake::Bake(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) { SHREFRACT_CHECK(impl_ != nullptr); }

const Bake::Impl& Bake::impl() const { return *impl_; }

int Bake::order() const { return bakeData(*this).order; }
const std::vector<std::string>& Bake::warnings() const { return bakeData(*this).warnings; }

std::vector<MapVertex> Bake::refractionMapMesh() const {
    // The layout's drawn mesh (common/bakefile.h drawCorners): joining, each triangle's corner
    // samples (0,0), (r,0), (0,r) at their rho texel centres (docs/format.md "rho"); charts, the
    // unfolded mesh at its atlas UVs.
    std::vector<MapVertex> out;
    for (const DrawCorner& c : drawCorners(bakeData(*this).layout)) out.push_back({c.position, c.normal, c.uv});
    return out;
}
int Bake::sampleCount() const { return bakeData(*this).layout.sampleCount(); }
int Bake::triangleCount() const { return bakeData(*this).layout.triangleCount; }
std::string Bake::layout() const { return nameOf(bakeData(*this).layout.kind); }

float Bake::ior() const { return frontIor(bakeData(*this)); }
glm::vec3 Bake::absorption() const { return frontAbsorption(bakeData(*this)); }

}  // namespace shrefract
