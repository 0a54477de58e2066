// Lat-long (equirectangular) environment images on the CPU: loading and the bilinear lookup.
// The runtime resamples this lookup into its cube map; the reference renderer calls it directly.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace shrefract {

// Convention (docs/runtime.md "Environment"): +y up; direction d maps to
// u = 0.5 + atan2(d.x, -d.z) / 2pi, v = acos(d.y) / pi, row 0 at the top.
struct LatLongImage {
    int width = 0, height = 0;
    std::vector<float> rgb;  // row-major, row 0 = top (+y)
};

// Reads an RGB(A) EXR; throws InputError naming the file.
LatLongImage loadLatLong(const std::string& path);

// Bilinear lookup at unit direction d: wraps in u, clamps in v at the poles.
glm::vec3 sampleLatLong(const LatLongImage& image, glm::vec3 d);
glm::vec3 sampleLatLong(int width, int height, const std::vector<float>& rgb, glm::vec3 d);

}  // namespace shrefract
