// The decompression shader generator (paper §5.1, Figure 3).
//
// Each stored SH function y_l^m (even parity, l + m even) is expanded into its exact Cartesian
// polynomial (common/sh.h), and the polynomials are distributed over fragment passes greedily by
// evaluation cost under per-pass limits. A pass evaluates every monomial x^a y^b z^c it needs
// once, then accumulates weight x polynomial into one RGBA32F target (exit x, y, z, length),
// adding to the partial sum of the passes before it (ping-pong).
//
// Cost model (an estimate of scalar ALU instructions, the R300 "64 ALU" budget):
//  - a monomial of degree >= 2 costs 1 MUL, built from one already in the pass (x, y, z free);
//  - a polynomial of n terms costs n (MUL then MADs, coefficients pre-multiplied by the scale);
//  - accumulating weight x value into the partial sum costs 1 (a vec4 MAD);
//  - each pass costs 1 more for its output.
// Texture units per pass: the local-view texture, the partial sum (every pass but the first),
// and one unit per weight texture, or a single unit for all when weights are a 2D array.
//
// A second form, ShForm::Recurrence, evaluates the same functions by the normalized associated
// Legendre recurrence instead (common/sh.cpp's shEvalEven, unrolled): better in float32 at high
// orders, where the expanded polynomials lose ~log10(absSum) digits to cancellation. Its cost
// model (same units):
//  - (x + iy)^m = re_m + i im_m by repeated complex multiplication: 4 per m >= 2 (m = 0, 1 free);
//  - column m, Q_l^m = Pbar_l^m / s^m for l = m..top (all l, odd parity too, as intermediates):
//    Q_m^m a literal (free), Q_{m+1}^m = literal * z costs 1, each further l costs 3
//    (a (z Q_{l-1} - b Q_{l-2}): MUL, MAD, MUL);
//  - a function: m = 0 accumulates Q_l^0 (1); m != 0 multiplies by re_m or im_m (1) and
//    accumulates (1);
//  - each pass costs 1 more for its output.
// A pass computes the powers through its largest |m| and each column through its largest l, so
// a function's marginal cost is what its power and column add to what the pass already has.
#pragma once

#include <string>
#include <vector>

#include "shrefract/runtime.h"

namespace shrefract {

struct ShaderLimits {
    std::string name = "modern";
    int maxTextureUnits = 16;     // samplers one pass may use
    int maxAluInstructions = 0;   // cost-model estimate per pass; <= 0: unlimited
    bool weightArray = true;      // all weights in one sampler2DArray (one unit)
    std::string version = "330 core";  // the #version line
    // The weights are RGBA8 UNORM codes (8-bit bakes uploaded as stored): each fetch becomes
    // texel * uWeightScale[k] + uWeightOffset[k] (per-coefficient uniforms; +1 ALU a function).
    bool unormWeights = false;
    // Textures fetched in the vertex shader (the direct path draws the sample grid as a mesh and
    // fetches D per vertex). The paper's R300 class had no vertex texture fetch.
    bool vertexTextureFetch = true;
};

// Paper2006: the ATI R300 class the paper used (Radeon 9700: 16 samplers, 64 ALU instructions
// per pass, one weight texture per function, no vertex texture fetch). Modern:
// `maxTextureUnits` (GL's GL_MAX_TEXTURE_IMAGE_UNITS), unlimited ALU, weights in a 2D array: one
// pass.
ShaderLimits shaderPreset(ShaderPreset preset, int maxTextureUnits = 16);

// How each SH function is evaluated in GLSL (ShForm, shrefract/runtime.h): Polynomial is the
// expanded Cartesian polynomial with exact integer coefficients x scale (paper §5.1); Recurrence
// the associated Legendre recurrence with (x + iy)^m, float32 throughout; Auto the recurrence
// from order kRecurrenceFromOrder on, the polynomial below it.

// The order from which ShForm::Auto uses the recurrence: the first order where the polynomial's
// float32 error is 10x the recurrence's or more. Measured (scripts/bench-shforms, llvmpipe,
// octahedron bake, weights uniform in [-1, 1], max |GL - double reference| over 4 views x ~1k
// samples x 4 channels; docs/runtime.md "Polynomial vs recurrence"):
//   order 8: polynomial 1.5e-5, recurrence 5.9e-6 (2.5x)    order 11: 6.3e-5 vs 1.3e-5 (5x)
//   order 12: 2.9e-4 vs 1.7e-5 (18x)    order 16: 8.9e-3 vs 3.1e-5 (290x)    20: 0.34 vs 6.0e-5
// Below 12 both are ~1e-5 or less, and on llvmpipe the recurrence takes 1.1-3x the polynomial's
// time (ms polynomial / recurrence, two runs: order 8 1.0 / 1.2-2.3, 12 1.2-2.8 / 2.6-5.4,
// 16 2.4-3.5 / 6.7-7.4), although its estimated ALU is 2-3x lower; under the "2006" limits it
// needs about half the passes.
constexpr int kRecurrenceFromOrder = 12;

// What `form` means at `order` (Auto resolved; the others unchanged).
ShForm resolveShForm(ShForm form, int order);

// What a sampler uniform of a pass binds.
struct SamplerBinding {
    // WeightRange: the grid basis's 8-bit dequantization, texel (k, 0) the scale and (k, 1) the
    // offset of layer k (a texture: a 16x32 grid's 512 layers outgrow the uniform arrays).
    enum Kind { LocalView, PartialSum, Weight, WeightArray, WeightRange } kind;
    int coefficient = -1;  // even index k for Weight
    std::string name;      // the GLSL uniform
};

struct DecompressionPass {
    std::vector<int> functions;  // even indices k, ascending
    int aluCost = 0;
    std::vector<SamplerBinding> samplers;
    // The generated part alone: the weight samplers (and u8 scale/offset uniforms) and
    //   vec4 shPass(ivec2 p, vec3 w, vec4 s)
    // returning s plus weight(p) x y_k(w) for this pass's functions. Any template with the line
    // "#pragma shrefract_generated" can take it (shaders/decompress.frag, shade_direct.vert).
    std::string generated;
    std::string fragment;  // the whole fragment shader: shaders/decompress.frag filled in
};

struct DecompressionShaders {
    int order = 0;
    int gridTheta = 0, gridPhi = 0;  // the grid basis (generateGridDecompression); 0: SH
    ShaderLimits limits;
    ShForm form = ShForm::Polynomial;  // the form generated (never Auto)
    std::string vertex;  // full-screen triangle from gl_VertexID
    std::vector<DecompressionPass> passes;
    // "order 8, limits 2006: 7 passes (ALU 63 61 ...; units 16 16 ...)", plus ", recurrence"
    // for that form
    std::string summary() const;
};

// Generates y_k for the shEvenCount(order) stored functions in `form` and distributes them into
// passes: first-fit decreasing by standalone cost, each candidate charged its marginal cost
// (monomials, powers and column entries the pass already has are free). Throws
// std::invalid_argument when one function alone exceeds the limits. Auto falls back to the
// polynomial form where the recurrence does not fit the limits (the "2006" preset above order
// 16: y_L^L alone needs the powers (x + iy)^2..L, 4 (L - 1) + 3 > 64 ALU).
DecompressionShaders generateDecompression(int order, const ShaderLimits& limits,
                                           ShForm form = ShForm::Auto);

// The grid basis (BakeData::basis Grid): one pass whose shPass fetches the four weight layers
// around w (shaders/grid_eval.glsl) and blends them: 4 fetches whatever the grid. Needs
// limits.weightArray (std::invalid_argument otherwise: the "2006" preset's one texture per
// coefficient cannot reach 512 layers).
DecompressionShaders generateGridDecompression(int nTheta, int nPhi, const ShaderLimits& limits);

// Writes decompress.vert, decompress_passN.frag and passes.txt into `dir` (created); throws
// std::runtime_error naming the file on failure.
void dumpShaders(const DecompressionShaders& shaders, const std::string& dir);

}  // namespace shrefract
