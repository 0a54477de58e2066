// The methods the paper compares with (its Figure 11), in GLSL, for evaluation
// (docs/evaluation.md): single-sided refraction and Wyman 2005 two-sided image-space refraction.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "shrefract/runtime.h"

namespace shrefract {

enum class BaselineMethod {
    Single,  // refract once at the front surface, look up the environment
    Wyman,   // Wyman 2005: second interface from a back-face normal/depth pass
};
template <> struct EnumNames<BaselineMethod> {
    static constexpr const char* what = "baseline method";
    static constexpr NamedValue<BaselineMethod> table[] = {{BaselineMethod::Single, "single"},
                                                           {BaselineMethod::Wyman, "wyman"}};
};

// Wyman's slides list three answers to total internal reflection at the second interface.
enum class WymanTir {
    Reflect,   // mirror T1 about the back normal (the bake's rule: TIR reflects); default
    Straight,  // continue along T1
    Grazing,   // refract at the critical angle: T1 projected onto the back surface's plane
};
template <> struct EnumNames<WymanTir> {
    static constexpr const char* what = "Wyman TIR rule";
    static constexpr NamedValue<WymanTir> table[] = {{WymanTir::Reflect, "reflect"},
                                                     {WymanTir::Straight, "straight"},
                                                     {WymanTir::Grazing, "grazing"}};
};

struct BaselineOptions {
    BaselineMethod method = BaselineMethod::Wyman;
    WymanTir tir = WymanTir::Reflect;
    bool timings = false;                    // GL timer queries around each pass (they stall)
    bool toneMap = false;                    // draw display values (toneMap()) instead of HDR
    float exposure = 1.0f;
    // Absorption kappa per RGB channel and object-space unit, instead of the bake's media
    // (Bake::absorption()): tinted glass without re-baking, as the paths do not depend on it.
    std::optional<glm::vec3> absorption;
    void* (*loader)(const char*) = nullptr;  // GL function loader; nullptr: guess from context
};

// GPU time per pass of the last draw(), milliseconds.
struct BaselineTimings {
    double backFaces = 0;  // Wyman pass 1: back-face normals and depth (0 for single)
    double shade = 0;      // the front-surface pass
};

class Baseline {
public:
    // Uploads the bake's mesh (its layout's triangle corners) in the current context. Wyman needs
    // d_N, the distance along the inward normal to the far side, per drawn point: per bake
    // sample for a joining bake (only triangle corners are read), per chart vertex for a chart
    // bake. Compute it by ray casting, e.g. eval/reference.h normalDistances().
    static std::unique_ptr<Baseline> create(const Bake& bake, const std::vector<float>& normalDistance,
                                            const BaselineOptions& options = {});
    ~Baseline();
    // Shades the object into the bound framebuffer (draw buffer 0: linear HDR colour; draw
    // buffer 1: world exit direction + coverage 1), like Refractor::draw. The back-face buffer
    // has the size of the current viewport.
    void draw(const glm::mat4& view, const glm::mat4& projection, const glm::mat4& model,
              const Environment& environment);
    const BaselineTimings& timings() const;
    void setTimings(bool on);  // GL timer queries per pass (BaselineOptions::timings)
    bool timingsEnabled() const;

    struct Impl;

private:
    explicit Baseline(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace shrefract
