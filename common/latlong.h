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

// Reads an RGB(A) EXR and checks it (checkLatLong); throws InputError naming the file: missing,
// not an OpenEXR image, a shrefract bake or another file without colour channels, a bad image.
LatLongImage loadLatLong(const std::string& path);

// What is wrong with a lat-long image, or "" when it is usable: the width must be twice the
// height (+-1 pixel; 101 x 37 or 16384 x 8 is no panorama), at most 65536 wide, and every value
// finite (a NaN or inf pixel spreads into every output pixel that filters it).
std::string latLongProblem(int width, int height, const std::vector<float>& rgb);

// Bilinear lookup at unit direction d: wraps in u, clamps in v at the poles.
glm::vec3 sampleLatLong(const LatLongImage& image, glm::vec3 d);
glm::vec3 sampleLatLong(int width, int height, const std::vector<float>& rgb, glm::vec3 d);

// The runtime's cube map of a lat-long image (runtime/src/environment.cpp uploads exactly these
// faces): OpenGL face order +x, -x, +y, -y, +z, -z; texel (x, y) of a face holds
// sampleLatLong at the direction through its centre, row y = 0 uploaded first (t = 0).
struct CubeMapImage {
    int faceSize = 0;
    std::vector<float> faces[6];  // RGB, faceSize^2 texels each
};
// faceSize 0: height / 2 (the runtime's default).
CubeMapImage cubeFromLatLong(const LatLongImage& image, int faceSize = 0);
// The direction through (s, t) in [-1, 1]^2 of face f, OpenGL's face orientation table.
glm::vec3 cubeFaceDirection(int face, float s, float t);
// GL_LINEAR lookup with seamless cube filtering, as the GL spec selects faces (major axis) and
// coordinates: a bilinear tap past a face edge reads the neighbour face's nearest texel.
glm::vec3 sampleCube(const CubeMapImage& cube, glm::vec3 d);

}  // namespace shrefract
