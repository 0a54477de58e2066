#include "common/latlong.h"

#include <algorithm>
#include <cmath>

#include <ImfArray.h>
#include <ImfRgbaFile.h>

#include "common/error.h"

namespace shrefract {

LatLongImage loadLatLong(const std::string& path) {
    LatLongImage img;
    try {
        Imf::RgbaInputFile file(path.c_str());
        Imath::Box2i dw = file.dataWindow();
        img.width = dw.max.x - dw.min.x + 1;
        img.height = dw.max.y - dw.min.y + 1;
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
    } catch (const std::exception& e) {
        throw inputError(path, std::string("cannot read environment EXR: ") + e.what());
    }
    if (img.width < 2 || img.height < 1) throw inputError(path, "environment image is empty");
    return img;
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

}  // namespace shrefract
