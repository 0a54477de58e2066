// A render's evaluation buffer: what every method (sh, single, wyman, raytrace) writes and
// `shrefract-eval image` compares. One EXR layout, docs/format.md "Evaluation buffer".
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace shrefract {

struct EvalBuffer {
    int width = 0, height = 0;
    // Per pixel, row-major, row 0 = top: linear HDR colour (background included) and coverage
    // (1 where the object covers the pixel centre, else 0) ...
    std::vector<glm::vec4> color;
    // ... and the world-space exit direction the method used (unit; zero where not covered).
    std::vector<glm::vec3> direction;

    size_t pixelCount() const { return static_cast<size_t>(width) * height; }
    bool covered(size_t i) const { return color[i].a > 0.5f; }
};

// Builds one from two RGBA float images (RenderedFrame's colour and directions, whose A is the
// coverage): colour RGB from the first, A and xyz from the second.
EvalBuffer makeEvalBuffer(int width, int height, const std::vector<float>& colorRgba,
                          const std::vector<float>& directionRgba);

// Channels R, G, B, A (FLOAT), dir.X, dir.Y, dir.Z (FLOAT); ZIP; attribute "shrefractEval" = 1.
// Written through writeAtomically (common/output.h): InputError for a refused target, IoError
// with the OS's reason for a failed write; either leaves `path` as it was.
void writeEvalBuffer(const std::string& path, const EvalBuffer& buffer);
// Reads that layout; a file without the dir.* channels is an InputError.
EvalBuffer readEvalBuffer(const std::string& path);

}  // namespace shrefract
