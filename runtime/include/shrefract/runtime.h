// The shrefract runtime: decompresses a bake's SH weights for the current viewpoint on the GPU,
// builds the seamless refraction map and shades the glass object (paper §5, docs/runtime.md).
// Every GL entry point uses the caller's current OpenGL 3.3+ core context.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "shrefract/enum_names.h"

namespace shrefract {

// A vertex of the mesh the refraction map is laid out for (Bake::refractionMapMesh).
struct MapVertex {
    glm::vec3 position;  // object space
    glm::vec3 normal;    // unit shading normal, object space
    glm::vec2 uv;        // refraction-map texture coordinate (the rho layout), texel centres
};

// A loaded bake, cheap to copy (shared, immutable).
class Bake {
public:
    int order() const;          // L stored (0 for a grid-basis bake: docs/format.md "weights")
    int sampleCount() const;    // |O_d|
    int triangleCount() const;
    // The surface layout: "joining" (paper §5.3: every triangle on a barycentric grid, seamless),
    // "isolated" (paper §5.2: charts in an atlas with gutters) or "uv" (the mesh's own UVs).
    std::string layout() const;
    float ior() const;          // manifest media[0].ior, else 1.5
    glm::vec3 absorption() const;  // manifest media[0].absorption (kappa per RGB), else 0
    // What loading noticed that the app should show its user, e.g. an older format version
    // whose data cannot be verified.
    const std::vector<std::string>& warnings() const;
    // The mesh refractionMap() is laid out for, three vertices per triangle (no index buffer):
    // an app that shades the glass in its own material draws these and samples the map at uv
    // (docs/integrate.md).
    std::vector<MapVertex> refractionMapMesh() const;

    // What loading made, opaque to apps (the project's own tools and tests read it through
    // runtime/src/bake_data.h).
    struct Impl;
    Bake() = default;  // empty: loadBake() makes the ones to use
    explicit Bake(std::shared_ptr<const Impl> impl);
    const Impl& impl() const;

private:
    std::shared_ptr<const Impl> impl_;
};

// Reads NAME.shrefract.exr and checks every part against its checksum (`verify` false skips
// that: faster, but a corrupt file may then draw garbage); throws InputError naming the file
// and the problem (missing, corrupt, newer format).
Bake loadBake(const std::string& path, bool verify = true);

// An HDR environment as a GL cube map (RGB32F, seamless), with a mip chain prefiltered for spread
// shading: level l >= 1 is level 0 convolved with a vMF lobe one texel of that level wide
// (docs/runtime.md "Spread shading"; built on the CPU at load, about a third more memory).
// Lat-long convention: +y up; u = 0.5 + atan2(d.x, -d.z) / 2pi, v = acos(d.y) / pi (row 0 top).
class Environment {
public:
    // Loads a lat-long EXR into a cube map of `faceSize` (0: height / 2); throws InputError naming
    // the file: missing, not an image, a bake, not 2:1 (+-1 pixel), NaN or inf pixels.
    static Environment loadLatLong(const std::string& path, int faceSize = 0);
    // Builds the cube map from lat-long RGB floats, row-major, row 0 = top (+y): 2:1 (+-1 pixel),
    // every value finite, else std::invalid_argument.
    static Environment fromLatLong(int width, int height, const std::vector<float>& rgb,
                                   int faceSize = 0);
    Environment(Environment&&) noexcept;
    Environment& operator=(Environment&&) noexcept;
    ~Environment();
    unsigned cubeMap() const { return texture_; }  // GL_TEXTURE_CUBE_MAP name
    int faceSize() const { return faceSize_; }  // of level 0
    int levels() const { return levels_; }      // mip levels, down to 1 x 1
    // Draws the environment behind everything (no depth test, no depth write): linear HDR, or
    // display values through toneMap() when `toneMap` (match RefractorOptions::toneMap).
    void drawBackground(const glm::mat4& view, const glm::mat4& projection, bool toneMap = false,
                        float exposure = 1.0f) const;

private:
    Environment() = default;
    unsigned texture_ = 0, program_ = 0, vao_ = 0;
    int faceSize_ = 0, levels_ = 1;
};

// HDR to display, documented once (docs/runtime.md): c * exposure, then the ACES filmic fit of
// Narkowicz 2015, clamped to [0, 1], then the sRGB transfer function.
glm::vec3 toneMap(glm::vec3 hdr, float exposure = 1.0f);

// GPU time per stage of the last update()/draw(), milliseconds (GL timer queries).
struct Timings {
    double view = 0;        // eye -> local view direction per sample
    double decompress = 0;  // D_mu, all generated passes (0 when the vertex shader decompresses)
    double smooth = 0;      // neighbour-list smoothing, texture-space for charts (0 when off)
    double unpack = 0;      // mu -> rho with correction texels (rho path); chart layouts: the gutters
    double shade = 0;       // draw() (with the decompression, when the vertex shader does it)
    int passes = 0;         // decompression passes used (0 when the vertex shader decompresses)
};

// GPU memory a Refractor allocated, bytes of texel and buffer storage at the internal formats it
// asked for (drivers may pad): what paper Figure 12 counts.
struct GpuMemory {
    size_t weights = 0;     // SH weights of the uploaded bands, mu size each, at the GPU format
                            // (RGBA32F, RGBA16F or RGBA8: see RefractorOptions::halfWeights)
    size_t samples = 0;     // positions and normals, RGB32F, mu size
    size_t rho = 0;         // rho index texture (rho path, or refractionMap() on the direct path);
                            // chart layouts: gutter rings and seam sources
    size_t neighbours = 0;  // smoothing lists (CSR)
    size_t mesh = 0;        // vertex and index buffers of the drawn mesh
    size_t targets = 0;     // render targets: local view, partial sums, smoothed, rho
    size_t total() const { return weights + samples + rho + neighbours + mesh + targets; }
};

// The shader limits the generated passes fit (docs/runtime.md "Shader generator"): Modern is one
// pass with the weights in a texture array; Paper2006 is the paper's ATI R300 class (16 samplers,
// 64 ALU instructions per pass, no vertex texture fetch).
enum class ShaderPreset { Modern, Paper2006 };
template <> struct EnumNames<ShaderPreset> {
    static constexpr const char* what = "shader preset";
    static constexpr NamedValue<ShaderPreset> table[] = {{ShaderPreset::Modern, "modern"},
                                                         {ShaderPreset::Paper2006, "2006"}};
};

// How the generated passes evaluate the SH functions: Polynomial (expanded Cartesian
// polynomials, the paper's), Recurrence (associated Legendre recurrence: fewer float32 digits
// lost at high orders) or Auto (the recurrence from the measured switch order on; docs/runtime.md
// "Polynomial vs recurrence").
enum class ShForm { Polynomial, Recurrence, Auto };
template <> struct EnumNames<ShForm> {
    static constexpr const char* what = "SH form";
    static constexpr NamedValue<ShForm> table[] = {{ShForm::Polynomial, "polynomial"},
                                                   {ShForm::Recurrence, "recurrence"},
                                                   {ShForm::Auto, "auto"}};
};

// How the refraction map is interpolated across triangles (docs/runtime.md "Interpolation
// paths"): Rho is the paper's texture-space layout with correction texels and an unpack pass;
// Direct draws the sample grid as a refined mesh and lets the rasterizer interpolate; Charts is
// the isolated-surface pipeline of chart bakes (paper §5.2, Figure 6).
enum class RefractorPath { Auto, Rho, Direct, Charts };
template <> struct EnumNames<RefractorPath> {
    static constexpr const char* what = "path";
    static constexpr NamedValue<RefractorPath> table[] = {{RefractorPath::Auto, "auto"},
                                                          {RefractorPath::Rho, "rho"},
                                                          {RefractorPath::Direct, "direct"},
                                                          {RefractorPath::Charts, "charts"}};
};

// Direct path: where the SH are evaluated. Vertex: in the shading pass's vertex shader (one
// draw; needs a one-pass preset and no smoothing); Texture: decompression passes into D_mu first.
enum class DecompressionSite { Auto, Vertex, Texture };
template <> struct EnumNames<DecompressionSite> {
    static constexpr const char* what = "decompression";
    static constexpr NamedValue<DecompressionSite> table[] = {{DecompressionSite::Auto, "auto"},
                                                              {DecompressionSite::Vertex, "vertex"},
                                                              {DecompressionSite::Texture, "texture"}};
};

// How the exit direction becomes a colour where the bake is unsure of it (its error model
// predicts an error, or, without one, the SH reconstruction is short), with a lobe
// RefractorOptions::spreadScale times that wide:
//   Auto (the default): Jitter on an SH bake, Blend on a grid-basis one;
//   Jitter: one direction drawn from the lobe, stable on the object, looked up over
//     the pixel's footprint: keeps the contrast the truth has;
//   Spread: the environment averaged over the lobe (a prefiltered cube map), widened by the
//     footprint: the lobe's mean;
//   Blend: the sharp lookup and the spread lobe mixed by the lobe's width;
//   Sharp: the paper's single lookup along the exit direction.
// The defaults follow scripts/study-shading and scripts/compare (object FLIP, detail ratio;
// docs/runtime.md).
enum class Shading { Auto, Jitter, Spread, Blend, Sharp };
template <> struct EnumNames<Shading> {
    static constexpr const char* what = "shading";
    static constexpr NamedValue<Shading> table[] = {{Shading::Auto, "auto"},
                                                    {Shading::Jitter, "jitter"},
                                                    {Shading::Spread, "spread"},
                                                    {Shading::Blend, "blend"},
                                                    {Shading::Sharp, "sharp"}};
};

struct RefractorOptions {
    ShaderPreset preset = ShaderPreset::Modern;
    // Where the recurrence does not fit the preset's limits (Paper2006 above order 16), Auto uses
    // the polynomial and Recurrence throws std::invalid_argument.
    ShForm form = ShForm::Auto;
    // Auto: Direct where the preset fetches textures in the vertex shader (Modern), Rho where it
    // cannot (Paper2006); Charts for chart bakes (isolated, uv), which take no other path
    // (std::invalid_argument).
    RefractorPath path = RefractorPath::Auto;
    // Auto: the measured default (docs/runtime.md "Interpolation paths").
    DecompressionSite decompression = DecompressionSite::Auto;
    int order = -1;                 // SH order used, -1: all uploaded; above maxOrder clamps
                                    // to it (order() tells); below -1: std::invalid_argument
    int maxOrder = -1;              // bands uploaded to the GPU, 0..maxOrder (-1: all stored);
                                    // setOrder() cannot go above it
    // Float32 bakes upload as RGBA16F (half the memory). f16 bakes are always RGBA16F, u8 bakes
    // RGBA8 with per-coefficient scale and offset applied in the shader (paper Figure 5).
    bool halfWeights = false;
    bool smoothing = false;         // spatial smoothing through the bake's neighbour lists
    bool correction = true;         // interpolation-correction texels in rho (paper §5.3.1)
    // Auto: jitter on an SH bake, blend on a grid-basis one, each the best by object FLIP with the
    // detail kept (docs/runtime.md "Shading where the bake is unsure"); shading() tells.
    Shading shading = Shading::Auto;
    float spreadScale = 0.15f;      // lobe width factor on the predicted error (docs/runtime.md)
    float footprintScale = 0.15f;   // screen-space footprint factor
    // Blend: the sharp lookup and the spread lobe mixed, the lobe's share sigma / (sigma +
    // blendSigma) for a lobe sigma radians wide (docs/runtime.md "Spread and blend").
    float blendSigma = 0.1f;
    // Jitter: one direction drawn from the spread lobe per cell of this size (a fraction of the
    // object's bounding-box diagonal; about two pixels where the object spans 400), the same in
    // every frame, instead of the lobe's mean (docs/runtime.md "Jitter").
    float jitterCell = 0.005f;
    // Jitter, gated by the lobe's width: at lobes this wide (radians) and wider, the draw is twice
    // the lobe and the lookup takes at least 0.4 of a pixel's turn of the exit; below 0.6 of it,
    // the draw is a third of the lobe; linear between (docs/runtime.md "The gate"). 0: ungated
    // (the draw is the lobe). Negative: std::invalid_argument.
    float jitterGate = 0.05f;
    // Lookups per pixel, averaged: 1 at its centre, or 4 at (+-1/4, +-1/4) pixel, which
    // antialiases the exit's pattern inside the pixel (docs/runtime.md "Four taps"). -1: the
    // measured default for the bake's basis, 4 on a grid-basis bake and 1 on SH; taps() tells.
    // Others: std::invalid_argument. Variable-IOR frames (setIor) take one.
    int taps = -1;
    // Spread shading takes the lobe width from the bake's error model, its predicted angular error
    // at each sample and view direction, where the bake has one (format version 3; docs/runtime.md
    // "Error model"); off, or on older bakes, from the SH reconstruction's length alone. Applies
    // where D_mu is decompressed in texture space, which auto decompression then picks; vertex
    // decompression, asked for, goes without it.
    bool errorModel = true;
    // Chart layouts (isolated, uv; paper §5.2): gutter rings filled around the charts by
    // dilation (-1: the bake's gutter; 0: none), and whether gutter texels next to a smooth seam
    // take the values across the cut instead (seam-aware filling, docs/runtime.md).
    int gutter = -1;
    bool seamAware = true;
    // GL timer queries around every stage, read through timings(). Off by default: each timed
    // stage waits for the GPU (docs/runtime.md "Benchmark"), so frames with them on stall.
    bool timings = false;
    bool toneMap = false;           // draw() writes display values (toneMap()) instead of HDR
    float exposure = 1.0f;
    // Absorption kappa per RGB channel and object-space unit, instead of the bake's media
    // (Bake::absorption()): tinted glass without re-baking, as the paths do not depend on it.
    std::optional<glm::vec3> absorption;
    void* (*loader)(const char*) = nullptr;  // GL function loader; nullptr: guess from context
};

// One frame's camera and the object's placement, given once per frame: update() builds the
// refraction map for this camera and draw() shades with the same one.
struct FrameView {
    glm::mat4 view{1.0f};        // world -> camera (e.g. glm::lookAt); the eye is its inverse's origin
    glm::mat4 projection{1.0f};  // camera -> clip
    glm::mat4 model{1.0f};       // object -> world
    glm::vec3 eye() const;       // world space
    // A camera at `eye` with the world's axes and no projection: for an app that only reads the
    // refraction map or D back, and draws nothing with it.
    static FrameView fromEye(glm::vec3 eye, const glm::mat4& model = glm::mat4(1.0f));
};

class Refractor {
public:
    // Uploads the bake and compiles the shaders in the current context; throws on GL failure.
    static std::unique_ptr<Refractor> create(const Bake& bake, const RefractorOptions& options = {});
    ~Refractor();
    // Builds the refraction map for this frame's camera and placement.
    void update(const FrameView& frame);
    // Shades the object, as seen by the last update()'s frame, into the bound framebuffer: colour
    // to draw buffer 0 (linear HDR unless toneMap), world exit direction + coverage 1 to draw
    // buffer 1 when one is bound. Before any update(): std::logic_error.
    void draw(const Environment& environment);
    // The refraction map for an app's own material: GL_TEXTURE_2D, RGBA32F, GL_LINEAR: the rho
    // layout (docs/integrate.md), or for chart bakes the atlas, in the mesh's own UV space for uv
    // bakes (looked up at the app's texture coordinates). On the direct path it is built on first
    // request (rho index and target allocated then) and kept up to date by every later update().
    unsigned refractionMap();
    glm::ivec2 refractionMapSize() const;
    RefractorPath path() const;               // Rho, Direct, or Charts for chart bakes
    DecompressionSite decompression() const;  // Texture or Vertex
    Shading shading() const;                  // as RefractorOptions::shading, Auto resolved
    int taps() const;                         // as RefractorOptions::taps, -1 resolved
    // Progressive decompression (paper §6): use bands 0..L, as RefractorOptions::order does:
    // -1 is all uploaded bands, above maxOrder clamps to it, below -1 is std::invalid_argument.
    void setOrder(int L);
    int order() const;
    void setSmoothing(bool on);
    // Chart layouts only (no effect on joining): gutter rings to fill (-1: the bake's), and
    // seam-aware filling on or off.
    void setGutter(int texels);
    int gutter() const;
    void setSeamAware(bool on);
    bool seamAware() const;
    void setCorrection(bool on);  // off only to show the seams it removes
    // Shades as if the object had index `ior` per RGB channel (different: dispersion), each in
    // [1, 5] (docs/runtime.md "Variable IOR and dispersion"). With one bake each channel's exit
    // interpolates between the straight path (index 1) and the baked one, the paper's §5.4
    // (which has no physical basis); with setIorBracket, between two bakes.
    void setIor(glm::vec3 ior);
    void resetIor();  // back to the bake's own index
    // A bake of the same mesh and layout at another index, interpolated with this one per
    // channel for setIor(); update() updates it too (its stage times add to timings()). It must
    // outlive this refractor or be unset (nullptr). Throws std::invalid_argument if the layouts
    // differ or the index is the same.
    void setIorBracket(Refractor* other);
    // GL timer queries per stage (RefractorOptions::timings); off zeroes timings().
    void setTimings(bool on);
    bool timingsEnabled() const;
    const Timings& timings() const;
    int passCount() const;  // decompression passes at the current order
    // The SH evaluation form of the current order's passes: Polynomial or Recurrence.
    ShForm form() const;
    const GpuMemory& memory() const;
    // Writes the generated GLSL of the current order into `dir`.
    void dumpShaders(const std::string& dir) const;
    // Reads back D_mu after update() (smoothed if on): 4 floats per sample, sample order.
    std::vector<float> readDirectionalMap() const;
    // Reads back the local view direction per sample after update() (4 floats per sample, xyz
    // used): what the decompression passes evaluated the SH at, for precision measurements.
    std::vector<float> readLocalViewMap() const;
    // Reads back the refraction map, rho layout, RGBA row-major from row 0 (builds it on the
    // direct path, as refractionMap() does).
    std::vector<float> readRefractionMap();

    struct Impl;

private:
    explicit Refractor(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace shrefract
