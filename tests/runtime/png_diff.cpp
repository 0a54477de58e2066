// png_diff A.png B.png MIN_FRACTION: the share of pixels whose largest channel difference exceeds
// 16/255 must be at least MIN_FRACTION (exit 0), else exit 1. Used by ViewerUnderXvfb to prove
// the glass was drawn: A has the object, B is the same view with the environment only.
#include <png.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

struct Image {
    int width = 0, height = 0;
    std::vector<unsigned char> rgb;
};

Image readPng(const std::string& path) {
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&image, path.c_str()))
        throw std::runtime_error(path + ": " + image.message);
    image.format = PNG_FORMAT_RGB;
    Image out;
    out.width = static_cast<int>(image.width);
    out.height = static_cast<int>(image.height);
    out.rgb.resize(PNG_IMAGE_SIZE(image));
    if (!png_image_finish_read(&image, nullptr, out.rgb.data(), 0, nullptr))
        throw std::runtime_error(path + ": " + image.message);
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: png_diff A.png B.png MIN_FRACTION\n");
        return 2;
    }
    try {
        Image a = readPng(argv[1]), b = readPng(argv[2]);
        if (a.width != b.width || a.height != b.height)
            throw std::runtime_error("sizes differ: " + std::to_string(a.width) + "x" +
                                     std::to_string(a.height) + " vs " + std::to_string(b.width) +
                                     "x" + std::to_string(b.height));
        size_t differing = 0, pixels = static_cast<size_t>(a.width) * a.height;
        for (size_t i = 0; i < pixels; ++i) {
            int d = 0;
            for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(a.rgb[3 * i + c] - b.rgb[3 * i + c]));
            differing += d > 16;
        }
        double fraction = static_cast<double>(differing) / pixels, minimum = std::atof(argv[3]);
        std::printf("png_diff: %.2f%% of %dx%d pixels differ (need >= %.2f%%)\n", 100 * fraction,
                    a.width, a.height, 100 * minimum);
        return fraction >= minimum ? 0 : 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "png_diff: %s\n", e.what());
        return 1;
    }
}
