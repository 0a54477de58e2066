// The samples of a joining bake as textures in the mu layout (positions and normals), and the
// full-screen triangle that covers them: what the decompression passes run over on the rho and
// direct pipelines (the direct one also fetches positions and normals per vertex).
#pragma once

#include <string>

#include "common/bakefile.h"
#include "pipeline.h"

namespace shrefract {

class SampleGrid : public SampleCover {
public:
    SampleGrid(const SurfaceLayout& layout, GpuMemory& memory);  // in the current context
    ~SampleGrid() override;
    SampleGrid(const SampleGrid&) = delete;
    SampleGrid& operator=(const SampleGrid&) = delete;

    const std::string& vertexShader() const override;
    void localView(glm::vec3 eyeObject) override;
    void draw() const override;
    bool partial() const override { return false; }
    GLuint positions() const { return position_; }  // RGB32F, mu layout
    GLuint normals() const { return normal_; }

private:
    GLuint position_ = 0, normal_ = 0, viewProgram_ = 0;
};

}  // namespace shrefract
