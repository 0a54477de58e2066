#include "common/latlong.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <ImfArray.h>
#include <ImfRgbaFile.h>
#include <ImfStringAttribute.h>

#include "common/error.h"
#include "common/exr_input.h"

namespace shrefract {

LatLongImage loadLatLong(const std::string& path) {
    LatLongImage img;
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw inputError(path, "file not found");
    if (!std::filesystem::is_regular_file(path, ec))
        throw inputError(path, "is not a regular file, not an environment image");
    checkExrHeaders(path);  // before OpenEXR allocates what a damaged header claims
    try {
        Imf::RgbaInputFile file(path.c_str());
        // A multi-part file (a shrefract bake) opens as its first part, which has no colour:
        // it would render black without a word.
        if (file.header().findTypedAttribute<Imf::StringAttribute>("shrefract.manifest"))
            throw inputError(path, "is a shrefract bake, not an environment image");
        if (!(file.channels() & Imf::WRITE_RGB) && !(file.channels() & Imf::WRITE_Y))
            throw inputError(path, "has no colour channels (R, G, B or Y): not an environment image");
        Imath::Box2i dw = file.dataWindow();
        img.width = dw.max.x - dw.min.x + 1;
        img.height = dw.max.y - dw.min.y + 1;
        const std::string size = latLongProblem(img.width, img.height, {});
        if (!size.empty()) throw inputError(path, size);
        const int w = img.width, h = img.height;
        Imf::Array2D<Imf::Rgba> pixels(h, w);
        file.setFrameBuffer(&pixels[0][0] - dw.min.x - dw.min.y * w, 1, w);
        file.readPixels(dw.min.y, dw.max.y);
        img.rgb.resize(static_cast<size_t>(w) * h * 3);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const Imf::Rgba& p = pixels[y][x];
                float* o = &img.rgb[(static_cast<size_t>(y) * w + x) * 3];
                o[0] = p.r;
                o[1] = p.g;
                o[2] = p.b;
            }
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw inputError(path, std::string("cannot read environment EXR: ") + e.what());
    }
    const std::string problem = latLongProblem(img.width, img.height, img.rgb);
    if (!problem.empty()) throw inputError(path, problem);
    return img;
}

std::string latLongProblem(int width, int height, const std::vector<float>& rgb) {
    const std::string size = std::to_string(width) + " x " + std::to_string(height);
    if (width < 2 || height < 1) return "environment image is " + size + ": empty";
    if (width > 65536) return "environment image is " + size + ": wider than 65536";
    if (std::abs(width - 2 * height) > 1)
        return "environment image is " + size +
               ": a lat-long image is twice as wide as high (+-1 pixel)";
    if (rgb.empty()) return "";
    if (rgb.size() != size_t(width) * size_t(height) * 3)
        return "environment image holds " + std::to_string(rgb.size()) + " values, expected " +
               size + " x 3";
    size_t bad = 0, first = 0;
    for (size_t i = 0; i < rgb.size(); ++i)
        if (!std::isfinite(rgb[i]) && bad++ == 0) first = i / 3;
    if (bad > 0)
        return std::to_string(bad) + " values are not finite (NaN or inf), the first at pixel (" +
               std::to_string(first % size_t(width)) + ", " + std::to_string(first / size_t(width)) +
               ")";
    return "";
}

glm::vec3 sampleLatLong(int w, int h, const std::vector<float>& rgb, glm::vec3 d) {
    float u = 0.5f + std::atan2(d.x, -d.z) / (2.0f * float(M_PI));
    float v = std::acos(std::clamp(d.y, -1.0f, 1.0f)) / float(M_PI);
    // Texel centres at (i + 0.5) / size, as GL_LINEAR samples a texture.
    float x = u * w - 0.5f, y = std::clamp(v * h - 0.5f, 0.0f, float(h - 1));
    int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    float fx = x - x0, fy = y - y0;
    auto at = [&](int xi, int yi) {
        xi = ((xi % w) + w) % w;
        yi = std::clamp(yi, 0, h - 1);
        const float* p = &rgb[(static_cast<size_t>(yi) * w + xi) * 3];
        return glm::vec3(p[0], p[1], p[2]);
    };
    return (1 - fx) * (1 - fy) * at(x0, y0) + fx * (1 - fy) * at(x0 + 1, y0) +
           (1 - fx) * fy * at(x0, y0 + 1) + fx * fy * at(x0 + 1, y0 + 1);
}

glm::vec3 sampleLatLong(const LatLongImage& image, glm::vec3 d) {
    return sampleLatLong(image.width, image.height, image.rgb, d);
}

glm::vec3 cubeFaceDirection(int f, float s, float t) {
    switch (f) {
        case 0: return {1, -t, -s};
        case 1: return {-1, -t, s};
        case 2: return {s, 1, t};
        case 3: return {s, -1, -t};
        case 4: return {s, -t, 1};
        default: return {-s, -t, -1};
    }
}

CubeMapImage cubeFromLatLong(const LatLongImage& image, int faceSize) {
    CubeMapImage cube;
    cube.faceSize = faceSize > 0 ? faceSize : std::max(1, image.height / 2);
    const int n = cube.faceSize;
    for (int f = 0; f < 6; ++f) {
        std::vector<float>& face = cube.faces[f];
        face.resize(static_cast<size_t>(n) * n * 3);
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                glm::vec3 d = glm::normalize(cubeFaceDirection(f, 2.0f * (x + 0.5f) / n - 1.0f,
                                                               2.0f * (y + 0.5f) / n - 1.0f));
                glm::vec3 c = sampleLatLong(image, d);
                float* o = &face[(static_cast<size_t>(y) * n + x) * 3];
                o[0] = c.r, o[1] = c.g, o[2] = c.b;
            }
    }
    return cube;
}

namespace {

// GL 4.5 spec table 8.19: the major axis picks the face; (sc, tc) / |ma| in [-1, 1].
struct FaceCoord {
    int face;
    float s, t;  // [-1, 1] on the face
};
FaceCoord faceOf(glm::vec3 d) {
    const glm::vec3 a = glm::abs(d);
    int f;
    float sc, tc, ma;
    if (a.x >= a.y && a.x >= a.z) {
        f = d.x >= 0 ? 0 : 1, ma = a.x, sc = d.x >= 0 ? -d.z : d.z, tc = -d.y;
    } else if (a.y >= a.z) {
        f = d.y >= 0 ? 2 : 3, ma = a.y, sc = d.x, tc = d.y >= 0 ? d.z : -d.z;
    } else {
        f = d.z >= 0 ? 4 : 5, ma = a.z, sc = d.z >= 0 ? d.x : -d.x, tc = -d.y;
    }
    return {f, sc / ma, tc / ma};
}

}  // namespace

glm::vec3 sampleCube(const CubeMapImage& cube, glm::vec3 d) {
    const FaceCoord c = faceOf(d);
    const int n = cube.faceSize;
    const float x = (c.s + 1.0f) * 0.5f * n - 0.5f, y = (c.t + 1.0f) * 0.5f * n - 0.5f;
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    const float fx = x - x0, fy = y - y0;
    // A tap inside the face reads its texel; one past an edge reads, like GL's seamless cube
    // filtering, the neighbour face: the texel nearest to where the direction through the tap's
    // (extended) centre meets the cube.
    auto at = [&](int xi, int yi) {
        int f = c.face;
        if (xi < 0 || yi < 0 || xi >= n || yi >= n) {
            const FaceCoord o = faceOf(cubeFaceDirection(f, 2.0f * (xi + 0.5f) / n - 1.0f,
                                                         2.0f * (yi + 0.5f) / n - 1.0f));
            f = o.face;
            xi = static_cast<int>(std::floor((o.s + 1.0f) * 0.5f * n));
            yi = static_cast<int>(std::floor((o.t + 1.0f) * 0.5f * n));
        }
        xi = std::clamp(xi, 0, n - 1), yi = std::clamp(yi, 0, n - 1);
        const float* p = &cube.faces[f][(static_cast<size_t>(yi) * n + xi) * 3];
        return glm::vec3(p[0], p[1], p[2]);
    };
    return (1 - fx) * (1 - fy) * at(x0, y0) + fx * (1 - fy) * at(x0 + 1, y0) +
           (1 - fx) * fy * at(x0, y0 + 1) + fx * fy * at(x0 + 1, y0 + 1);
}

}  // namespace shrefract
