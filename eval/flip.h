// LDR-FLIP (Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström, Fairchild, "FLIP: A Difference
// Evaluator for Alternating Images", HPG 2020), written from the paper: the per-pixel difference a
// viewer sees when flipping between two display-encoded images (docs/evaluation.md "Object metrics
// and FLIP").
#pragma once

#include <cmath>
#include <vector>

#include <glm/glm.hpp>

namespace shrefract {

// Pixels per degree of visual angle for a viewer `distance` metres from a monitor `width` metres
// wide showing `pixels` columns. The paper's default viewing conditions (0.7 m from a 0.7 m wide
// 3840-pixel monitor) give 67.02.
constexpr float pixelsPerDegree(float distance = 0.7f, float width = 0.7f, float pixels = 3840.0f) {
    return static_cast<float>(distance * (pixels / width) * M_PI / 180.0);
}

// Per-pixel LDR-FLIP in [0, 1] (0: identical) between two sRGB-encoded images with values in
// [0, 1] (others are clamped), `width` x `height`, row-major, seen at `ppd` pixels per degree.
// Throws InputError if a size differs or ppd is not positive.
std::vector<float> flipMap(const std::vector<glm::vec3>& ref, const std::vector<glm::vec3>& test,
                           int width, int height, float ppd = pixelsPerDegree());

}  // namespace shrefract
