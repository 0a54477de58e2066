// The isolated-surface pipeline (paper §5.2, Figure 6) for chart layouts (isolated, uv), beside
// the joining one in refractor.cpp, which calls into it at each stage:
//   local view   the unfolded mesh drawn in texture space (chart_texture.vert, chart_view.frag);
//   D_mu         the generated decompression passes, rasterizing the same mesh: only the
//                covered texels are decompressed (drawFootprint);
//   D+_mu        dilation into the gutters, one pass per ring (dilate.frag), then seam-aware
//                sources (seam_fill.frag);
//   smoothing    a local filter in texture space (smooth_atlas.frag);
// and the result is the refraction map in the atlas layout, for the shading pass or the app's
// own material. The CPU twin is common/decompress.h chartRefractionMap.
#pragma once

#include <cstddef>

#include <glm/glm.hpp>

#include "common/bakefile.h"
#include "gl.h"

namespace shrefract {

class ChartPipeline {
public:
    // In the current context; `meshVao` draws the unfolded mesh (position, normal, atlas UV at
    // attributes 0, 1, 2), `vertices` of it. Throws std::runtime_error on GL failure.
    ChartPipeline(const SurfaceLayout& layout, GLuint meshVao, int vertices, int dilation,
                  bool seamAware);
    ~ChartPipeline();
    ChartPipeline(const ChartPipeline&) = delete;
    ChartPipeline& operator=(const ChartPipeline&) = delete;

    // The vertex shader that draws the unfolded mesh in texture space: decompression passes link
    // with it instead of the full-screen triangle.
    static const std::string& textureSpaceVertexShader();
    // The local view direction of every covered texel into the bound framebuffer (atlas-sized).
    void localView(glm::vec3 eyeObject);
    // Rasterizes the unfolded mesh in texture space with the program in use.
    void drawFootprint() const;
    // D -> D+: the dilation rings and the seam-aware sources. The last pass writes into
    // `outFbo` when it is not 0; returns the texture holding D+ otherwise.
    GLuint fillGutters(GLuint d, GLuint outFbo);
    // The 3 x 3 texture-space smoothing of `src` into `outFbo`.
    void smooth(GLuint src, GLuint outFbo);

    void setDilation(int width);  // rings filled; 0: no gutters
    int dilation() const { return dilation_; }
    void setSeamAware(bool on) { seamAware_ = on; }
    bool seamAware() const { return seamAware_; }
    // Texture bytes of the ring map, the seam sources and the two ping-pong targets.
    size_t indexBytes() const;
    size_t targetBytes() const;

private:
    void uploadRings();
    void pass(GLuint program, GLuint src, GLuint dstFbo);

    const SurfaceLayout& layout_;
    GLuint meshVao_ = 0, emptyVao_ = 0;
    int vertices_ = 0, width_ = 0, height_ = 0;
    int dilation_ = 0, seamEntries_ = 0, listWidth_ = 1;
    bool seamAware_ = true;
    GLuint viewProgram_ = 0, dilateProgram_ = 0, seamProgram_ = 0, smoothProgram_ = 0;
    GLuint rings_ = 0, seamIndex_ = 0, seamSample_ = 0, seamWeight_ = 0;
    GLuint pingTex_[2] = {0, 0}, pingFbo_[2] = {0, 0};
};

}  // namespace shrefract
