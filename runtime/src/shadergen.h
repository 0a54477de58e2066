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
#pragma once

#include <string>
#include <vector>

namespace shrefract {

struct ShaderLimits {
    std::string name = "modern";
    int maxTextureUnits = 16;     // samplers one pass may use
    int maxAluInstructions = 0;   // cost-model estimate per pass; <= 0: unlimited
    bool weightArray = true;      // all weights in one sampler2DArray (one unit)
    std::string version = "330 core";  // the #version line
};

// "2006": the ATI R300 class the paper used (Radeon 9700: 16 samplers, 64 ALU instructions per
// pass, one weight texture per function). "modern": `maxTextureUnits` (GL's
// GL_MAX_TEXTURE_IMAGE_UNITS), unlimited ALU, weights in a 2D array: one pass.
// Throws std::invalid_argument for other names.
ShaderLimits shaderPreset(const std::string& name, int maxTextureUnits = 16);

// What a sampler uniform of a pass binds.
struct SamplerBinding {
    enum Kind { LocalView, PartialSum, Weight, WeightArray } kind;
    int coefficient = -1;  // even index k for Weight
    std::string name;      // the GLSL uniform
};

struct DecompressionPass {
    std::vector<int> functions;  // even indices k, ascending
    int aluCost = 0;
    std::vector<SamplerBinding> samplers;
    std::string fragment;  // GLSL
};

struct DecompressionShaders {
    int order = 0;
    ShaderLimits limits;
    std::string vertex;  // full-screen triangle from gl_VertexID
    std::vector<DecompressionPass> passes;
    // "order 8, limits 2006: 7 passes (ALU 63 61 ..., units 16 16 ...)"
    std::string summary() const;
};

// Expands y_k for the shEvenCount(order) stored functions and distributes them into passes:
// first-fit decreasing by standalone cost, each candidate charged its marginal cost (monomials
// the pass already has are free). Throws std::invalid_argument when one function alone exceeds
// the limits.
DecompressionShaders generateDecompression(int order, const ShaderLimits& limits);

// Writes decompress.vert, decompress_passN.frag and passes.txt into `dir` (created); throws
// std::runtime_error naming the file on failure.
void dumpShaders(const DecompressionShaders& shaders, const std::string& dir);

}  // namespace shrefract
