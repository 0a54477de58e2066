#include "eval/image_eval.h"

#include <png.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "eval/directions.h"
#include "eval/flip.h"
#include "common/error.h"
#include "common/png.h"
#include "common/tonemap.h"

namespace shrefract {

namespace {

glm::vec3 toneMappedPixel(const EvalBuffer& b, size_t i, float exposure) {
    return toneMapAces(glm::vec3(b.color[i]), exposure);
}

// The tone-mapped image. toneMapAces ends with the sRGB transfer function (common/tonemap.h), so
// these are display-encoded values in [0, 1]: what LDR-FLIP takes, and flipMap gets them as they
// are (it decodes sRGB itself).
std::vector<glm::vec3> toneMappedColors(const EvalBuffer& b, float exposure) {
    std::vector<glm::vec3> c(b.pixelCount());
    for (size_t i = 0; i < c.size(); ++i) c[i] = toneMappedPixel(b, i, exposure);
    return c;
}

float luminance(glm::vec3 c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

void checkSameSize(const EvalBuffer& a, const EvalBuffer& b) {
    if (a.width != b.width || a.height != b.height)
        throw InputError("image sizes differ: " + std::to_string(a.width) + "x" +
                         std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                         std::to_string(b.height));
}

// The SSIM map over the windows that lie inside the image ('valid'): value (x, y) belongs to the
// window centred on pixel (x + kSsimRadius, y + kSsimRadius). Empty when the image is smaller
// than a window.
constexpr int kSsimRadius = 5;
struct SsimMap {
    std::vector<double> values;
    int width = 0, height = 0;
};

SsimMap ssimMap(const std::vector<float>& a, const std::vector<float>& b, int w, int h) {
    // Gaussian window 11x11, sigma 1.5, normalized (Wang et al. 2004), separable.
    constexpr int R = kSsimRadius;
    float g[2 * R + 1], sum = 0;
    for (int k = -R; k <= R; ++k) sum += g[k + R] = std::exp(-(k * k) / (2.0f * 1.5f * 1.5f));
    for (float& x : g) x /= sum;
    const double C1 = 0.01 * 0.01, C2 = 0.03 * 0.03;  // (K L)^2 with L = 1
    const size_t n = static_cast<size_t>(w) * h;
    // Five blurred images: mu_a, mu_b, E[a^2], E[b^2], E[ab]; rows first, then columns, over
    // the windows that lie inside the image ('valid').
    SsimMap m;
    if (w < 2 * R + 1 || h < 2 * R + 1) return m;
    std::vector<float> src[5];
    for (auto& s : src) s.resize(n);
    for (size_t i = 0; i < n; ++i) {
        src[0][i] = a[i], src[1][i] = b[i];
        src[2][i] = a[i] * a[i], src[3][i] = b[i] * b[i], src[4][i] = a[i] * b[i];
    }
    const int vw = w - 2 * R, vh = h - 2 * R;
    std::vector<double> blur[5];
    for (int k = 0; k < 5; ++k) {
        std::vector<double> rows(static_cast<size_t>(vw) * h);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < vw; ++x) {
                double s = 0;
                for (int j = 0; j <= 2 * R; ++j) s += g[j] * src[k][static_cast<size_t>(y) * w + x + j];
                rows[static_cast<size_t>(y) * vw + x] = s;
            }
        blur[k].resize(static_cast<size_t>(vw) * vh);
        for (int y = 0; y < vh; ++y)
            for (int x = 0; x < vw; ++x) {
                double s = 0;
                for (int j = 0; j <= 2 * R; ++j) s += g[j] * rows[static_cast<size_t>(y + j) * vw + x];
                blur[k][static_cast<size_t>(y) * vw + x] = s;
            }
    }
    m.width = vw, m.height = vh;
    m.values.resize(blur[0].size());
    for (size_t i = 0; i < blur[0].size(); ++i) {
        double ma = blur[0][i], mb = blur[1][i];
        double va = blur[2][i] - ma * ma, vb = blur[3][i] - mb * mb, cov = blur[4][i] - ma * mb;
        m.values[i] = ((2 * ma * mb + C1) * (2 * cov + C2)) / ((ma * ma + mb * mb + C1) * (va + vb + C2));
    }
    return m;
}

// Mean of the SSIM map over the windows whose centre pixel (an index into the w-wide image)
// `keep` accepts; NaN when there are none.
template <class Keep>
double ssimMean(const SsimMap& m, int w, Keep keep) {
    double total = 0;
    size_t count = 0;
    for (int y = 0; y < m.height; ++y)
        for (int x = 0; x < m.width; ++x)
            if (keep(static_cast<size_t>(y + kSsimRadius) * w + x + kSsimRadius)) {
                total += m.values[static_cast<size_t>(y) * m.width + x];
                ++count;
            }
    return count ? total / count : std::nan("");
}

// The whole image's mean; 1 for an image smaller than a window (no structure to compare).
double wholeSsim(const SsimMap& m, int w) {
    const double s = ssimMean(m, w, [](size_t) { return true; });
    return std::isnan(s) ? 1.0 : s;
}

// |L - G * L| per pixel, G a Gaussian of sigma 2 px (radius 6, separable, clamp to edge): the
// detail a blur of that width removes, a band-pass of the luminance.
std::vector<float> bandPassDetail(const std::vector<float>& l, int w, int h) {
    constexpr int R = 6;
    float g[2 * R + 1], sum = 0;
    for (int k = -R; k <= R; ++k) sum += g[k + R] = std::exp(-(k * k) / (2.0f * 2.0f * 2.0f));
    for (float& x : g) x /= sum;
    std::vector<float> rows(l.size()), out(l.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float s = 0;
            for (int j = -R; j <= R; ++j) s += g[j + R] * l[static_cast<size_t>(y) * w + std::clamp(x + j, 0, w - 1)];
            rows[static_cast<size_t>(y) * w + x] = s;
        }
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float s = 0;
            for (int j = -R; j <= R; ++j) s += g[j + R] * rows[static_cast<size_t>(std::clamp(y + j, 0, h - 1)) * w + x];
            const size_t i = static_cast<size_t>(y) * w + x;
            out[i] = std::abs(l[i] - s);
        }
    return out;
}

// A JSON number, or null where the quantity is undefined (NaN).
nlohmann::json numberOrNull(double v) { return std::isnan(v) ? nlohmann::json(nullptr) : nlohmann::json(v); }

// The legend strip under a heat map: the ramp across the width from 0 to maxValue, labelled "0"
// and `right`.
void drawLegend(Image8& img, int top, float maxValue, const std::string& right) {
    const int x0 = 4, x1 = std::max(x0 + 1, img.width - 4);
    for (int x = x0; x < x1; ++x) {
        glm::u8vec3 c = errorColor(maxValue * (x - x0) / float(x1 - x0 - 1), maxValue);
        for (int y = top + 2; y < top + 10; ++y) {
            uint8_t* p = img.at(x, y);
            p[0] = c.r, p[1] = c.g, p[2] = c.b;
        }
    }
    drawText(img, x0, top + 13, "0", {255, 255, 255}, 1);
    drawText(img, x1 - 6 * static_cast<int>(right.size()), top + 13, right, {255, 255, 255}, 1);
}

// 5x7 bitmap glyphs, row by row, '#' set. Upper case, digits and a little punctuation.
struct Glyph {
    char c;
    const char* rows;  // 35 characters
};
const Glyph kFont[] = {
    {'A', " ### #   ##   #######   ##   ##   #"}, {'B', "#### #   ##   ##### #   ##   ##### "},
    {'C', " ### #   ##    #    #    #   # ### "}, {'D', "#### #   ##   ##   ##   ##   ##### "},
    {'E', "######    #    #### #    #    #####"}, {'F', "######    #    #### #    #    #    "},
    {'G', " ### #   ##    # ####   ##   # ####"}, {'H', "#   ##   ##   #######   ##   ##   #"},
    {'I', " ###   #    #    #    #    #   ### "}, {'J', "  ###   #    #    #    # #  #  ##  "},
    {'K', "#   ##  # # #  ##   # #  #  # #   #"}, {'L', "#    #    #    #    #    #    #####"},
    {'M', "#   ### ### # ## # ##   ##   ##   #"}, {'N', "#   ##   ###  ## # ##  ###   ##   #"},
    {'O', " ### #   ##   ##   ##   ##   # ### "}, {'P', "#### #   ##   ##### #    #    #    "},
    {'Q', " ### #   ##   ##   ## # ##  #  ## #"}, {'R', "#### #   ##   ##### # #  #  # #   #"},
    {'S', " #####    #     ###     #    ##### "}, {'T', "#####  #    #    #    #    #    #  "},
    {'U', "#   ##   ##   ##   ##   ##   # ### "}, {'V', "#   ##   ##   ##   ##   # # #   #  "},
    {'W', "#   ##   ##   ## # ## # ## # # # # "}, {'X', "#   ##   # # #   #   # # #   ##   #"},
    {'Y', "#   ##   # # #   #    #    #    #  "}, {'Z', "#####    #   #   #   #   #    #####"},
    {'0', " ### #   ##  ### # ###  ##   # ### "}, {'1', "  #   ##    #    #    #    #   ### "},
    {'2', " ### #   #    #   #   #   #   #####"}, {'3', "#####   #   #     #     ##   # ### "},
    {'4', "   #   ##  # # #  # #####   #    # "}, {'5', "######    ####     #    ##   # ### "},
    {'6', "  ##  #   #    #### #   ##   # ### "}, {'7', "#####    #   #   #   #    #    #   "},
    {'8', " ### #   ##   # ### #   ##   # ### "}, {'9', " ### #   ##   # ####    #   #  ##  "},
    {'.', "                          ##   ##  "}, {',', "                     ##    #   #   "},
    {'-', "               #####               "}, {':', "      ##   ##        ##   ##       "},
    {'(', "   #   #   #    #    #     #     # "}, {')', " #     #     #    #    #   #   #   "},
    {'/', "    #   #    #   #   #    #   #    "}, {'%', "##   ##  #   #   #   #   #  ##   ##"},
    {'=', "          #####     #####          "}, {'_', "                              #####"},
    {'+', "       #    #  #####  #    #       "}, {'<', "   #   #   #   #     #     #     # "},
    {'>', " #     #     #     #   #   #   #   "},
};

const char* glyphRows(char c) {
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    for (const Glyph& g : kFont)
        if (g.c == c) return g.rows;
    return nullptr;
}

}  // namespace

std::vector<float> angularErrors(const EvalBuffer& ref, const EvalBuffer& test) {
    checkSameSize(ref, test);
    std::vector<float> e(ref.pixelCount(), -1.0f);
    for (size_t i = 0; i < e.size(); ++i) {
        if (!ref.covered(i) || !test.covered(i)) continue;
        glm::vec3 a = ref.direction[i], b = test.direction[i];
        float la = glm::length(a), lb = glm::length(b);
        double c = la > 0 && lb > 0 ? glm::dot(a / la, b / lb) : -1.0;
        e[i] = static_cast<float>(std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / M_PI);
    }
    return e;
}

double ssim(const std::vector<float>& a, const std::vector<float>& b, int w, int h) {
    return wholeSsim(ssimMap(a, b, w, h), w);
}

namespace {

// The colour keys of compareImages (psnr, psnrInterior, errorShare, ssim and the object keys):
// the tone-mapped colours cRef and cTest compared over the frame, the reference's interior and
// silhouette, and the object mask (the pixels the reference covers). `ref` gives the coverage only.
nlohmann::json colourMetrics(const EvalBuffer& ref, const std::vector<glm::vec3>& cRef,
                             const std::vector<glm::vec3>& cTest) {
    const int w = ref.width, h = ref.height;
    size_t cr = 0;
    double se = 0, seObject = 0;
    std::vector<float> la(ref.pixelCount()), lb(ref.pixelCount());
    for (size_t i = 0; i < ref.pixelCount(); ++i) {
        const bool a = ref.covered(i);
        cr += a;
        const glm::vec3 d = cRef[i] - cTest[i];
        se += glm::dot(d, d);
        if (a) seObject += glm::dot(d, d);
        la[i] = luminance(cRef[i]), lb[i] = luminance(cTest[i]);
    }
    const double mse = se / (3.0 * std::max<size_t>(1, ref.pixelCount()));
    const double psnr = mse > 0 ? 10.0 * std::log10(1.0 / mse) : 99.0;  // 99: identical
    // Where the squared error lies: silhouette pixels (the reference's coverage changes within
    // their 3 x 3 neighbourhood: the GL methods draw one sample per pixel there), the object's
    // interior, and the background; and the PSNR over the interior alone.
    double seClass[3] = {0, 0, 0};  // edge, interior, background
    size_t nInterior = 0;
    for (int y = 0; y < ref.height; ++y)
        for (int x = 0; x < ref.width; ++x) {
            const size_t i = static_cast<size_t>(y) * ref.width + x;
            bool edge = false;
            for (int dy = -1; dy <= 1 && !edge; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int xx = std::clamp(x + dx, 0, ref.width - 1), yy = std::clamp(y + dy, 0, ref.height - 1);
                    if (ref.covered(static_cast<size_t>(yy) * ref.width + xx) != ref.covered(i)) edge = true;
                }
            const glm::vec3 d = cRef[i] - cTest[i];
            const int cls = edge ? 0 : ref.covered(i) ? 1 : 2;
            seClass[cls] += glm::dot(d, d);
            nInterior += cls == 1;
        }
    const double seAll = std::max(1e-30, seClass[0] + seClass[1] + seClass[2]);
    const double mseInterior = seClass[1] / (3.0 * std::max<size_t>(1, nInterior));
    // What a viewer sees on the object (the pixels the reference covers), the silhouette included:
    // PSNR, SSIM, the detail kept and FLIP; undefined (null) without object pixels.
    const auto object = [&](size_t i) { return ref.covered(i); };
    const SsimMap ssims = ssimMap(la, lb, w, h);
    const std::vector<float> detailRef = bandPassDetail(la, w, h), detailTest = bandPassDetail(lb, w, h);
    const std::vector<float> flip = flipMap(cRef, cTest, w, h);
    double sumDetailRef = 0, sumDetailTest = 0, sumFlip = 0, sumFlipObject = 0;
    for (size_t i = 0; i < flip.size(); ++i) {
        sumFlip += flip[i];
        if (!object(i)) continue;
        sumDetailRef += detailRef[i], sumDetailTest += detailTest[i], sumFlipObject += flip[i];
    }
    const double nan = std::nan(""), mseObject = seObject / (3.0 * std::max<size_t>(1, cr));
    return {{"psnr", psnr},
            {"psnrInterior", mseInterior > 0 ? 10.0 * std::log10(1.0 / mseInterior) : 99.0},
            {"errorShare",
             {{"silhouette", seClass[0] / seAll}, {"interior", seClass[1] / seAll},
              {"background", seClass[2] / seAll}}},
            {"ssim", wholeSsim(ssims, w)},
            {"objectPsnr", numberOrNull(cr == 0 ? nan : mseObject > 0 ? 10.0 * std::log10(1.0 / mseObject) : 99.0)},
            {"objectSsim", numberOrNull(ssimMean(ssims, w, object))},
            {"detailRatio", numberOrNull(sumDetailRef > 0 ? sumDetailTest / sumDetailRef : nan)},
            {"objectFlip", numberOrNull(cr == 0 ? nan : sumFlipObject / cr)},
            {"flip", sumFlip / std::max<size_t>(1, flip.size())}};
}

}  // namespace

nlohmann::json compareImages(const EvalBuffer& ref, const EvalBuffer& test, float exposure) {
    checkSameSize(ref, test);
    const std::vector<float> e = angularErrors(ref, test);
    std::vector<double> angles;
    size_t cr = 0, ct = 0, both = 0, refOnly = 0, testOnly = 0;
    for (size_t i = 0; i < e.size(); ++i) {
        const bool a = ref.covered(i), b = test.covered(i);
        cr += a, ct += b, both += a && b, refOnly += a && !b, testOnly += b && !a;
        if (e[i] >= 0) angles.push_back(e[i]);
    }
    nlohmann::json r = colourMetrics(ref, toneMappedColors(ref, exposure), toneMappedColors(test, exposure));
    r["width"] = ref.width;
    r["height"] = ref.height;
    r["angleDeg"] = errorStats(angles);
    r["coverage"] = {{"ref", cr}, {"test", ct}, {"both", both}, {"refOnly", refOnly},
                     {"testOnly", testOnly}, {"mismatch", refOnly + testOnly}};
    return r;
}

nlohmann::json compareDisplayImage(const EvalBuffer& ref, const Image8& test, float exposure) {
    if (ref.width != test.width || ref.height != test.height)
        throw InputError("image sizes differ: " + std::to_string(ref.width) + "x" + std::to_string(ref.height) +
                         " vs " + std::to_string(test.width) + "x" + std::to_string(test.height));
    std::vector<glm::vec3> cTest(ref.pixelCount());
    for (size_t i = 0; i < cTest.size(); ++i)
        cTest[i] = glm::vec3(test.rgb[3 * i], test.rgb[3 * i + 1], test.rgb[3 * i + 2]) / 255.0f;
    size_t cr = 0;
    for (size_t i = 0; i < ref.pixelCount(); ++i) cr += ref.covered(i);
    nlohmann::json r = colourMetrics(ref, toneMappedColors(ref, exposure), cTest);
    r["width"] = ref.width;
    r["height"] = ref.height;
    r["coverage"] = {{"ref", cr}};
    return r;
}

Image8 readPng8(const std::string& path) {
    png_image png;
    std::memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&png, path.c_str()))
        throw InputError(path + ": not a readable PNG (" + png.message + ")");
    if (png.format & PNG_FORMAT_FLAG_LINEAR) {
        png_image_free(&png);
        throw InputError(path + ": a 16-bit PNG; expected 8 bits per channel (a display image)");
    }
    // As RGBA and the alpha dropped here: 8-bit sRGB output is never premultiplied, so the colour
    // is the file's whatever its alpha (a browser's canvas may leave alpha below 1).
    png.format = PNG_FORMAT_RGBA;
    std::vector<uint8_t> rgba(PNG_IMAGE_SIZE(png));
    if (!png_image_finish_read(&png, nullptr, rgba.data(), 0, nullptr)) {
        const std::string message = png.message;
        png_image_free(&png);
        throw InputError(path + ": cannot decode the PNG (" + message + ")");
    }
    Image8 out;
    out.resize(static_cast<int>(png.width), static_cast<int>(png.height));
    for (size_t i = 0; i < out.rgb.size() / 3; ++i)
        for (int c = 0; c < 3; ++c) out.rgb[3 * i + c] = rgba[4 * i + c];
    return out;
}

glm::u8vec3 errorColor(float degrees, float maxDegrees) {
    static const glm::vec3 stops[5] = {{20, 20, 120}, {0, 120, 255}, {0, 200, 80}, {255, 220, 0},
                                       {220, 0, 0}};
    float t = std::clamp(degrees / maxDegrees, 0.0f, 1.0f) * 4.0f;
    int k = std::min(3, static_cast<int>(t));
    glm::vec3 c = glm::mix(stops[k], stops[k + 1], t - k);
    return glm::u8vec3(glm::round(c));
}

Image8 toneMapped(const EvalBuffer& b, float exposure) {
    Image8 img;
    img.resize(b.width, b.height);
    for (size_t i = 0; i < b.pixelCount(); ++i) {
        glm::vec3 c = toneMappedPixel(b, i, exposure);
        for (int k = 0; k < 3; ++k) img.rgb[3 * i + k] = static_cast<uint8_t>(std::lround(c[k] * 255.0f));
    }
    return img;
}

Image8 heatMap(const EvalBuffer& ref, const EvalBuffer& test, float maxDegrees, float exposure) {
    const std::vector<float> e = angularErrors(ref, test);
    const int legend = 24;
    Image8 img;
    img.resize(ref.width, ref.height + legend);
    for (int y = 0; y < ref.height; ++y)
        for (int x = 0; x < ref.width; ++x) {
            const size_t i = static_cast<size_t>(y) * ref.width + x;
            uint8_t* p = img.at(x, y);
            glm::u8vec3 c;
            if (e[i] >= 0) c = errorColor(e[i], maxDegrees);
            else if (ref.covered(i) != test.covered(i)) c = {255, 0, 255};
            else c = glm::u8vec3(glm::round(toneMappedPixel(ref, i, exposure) * 255.0f * 0.25f));
            p[0] = c.r, p[1] = c.g, p[2] = c.b;
        }
    char right[32];
    std::snprintf(right, sizeof right, "%g DEG", maxDegrees);
    drawLegend(img, ref.height, maxDegrees, right);
    return img;
}

Image8 flipHeatMap(const EvalBuffer& ref, const EvalBuffer& test, float exposure) {
    checkSameSize(ref, test);
    const std::vector<float> flip =
        flipMap(toneMappedColors(ref, exposure), toneMappedColors(test, exposure), ref.width, ref.height);
    const int legend = 24;
    Image8 img;
    img.resize(ref.width, ref.height + legend);
    for (size_t i = 0; i < flip.size(); ++i) {
        const glm::u8vec3 c = errorColor(flip[i], 1.0f);
        img.rgb[3 * i] = c.r, img.rgb[3 * i + 1] = c.g, img.rgb[3 * i + 2] = c.b;
    }
    drawLegend(img, ref.height, 1.0f, "1 FLIP");
    return img;
}

void drawText(Image8& image, int x, int y, const std::string& text, glm::u8vec3 color, int scale) {
    for (size_t k = 0; k < text.size(); ++k) {
        const char* rows = glyphRows(text[k]);
        if (!rows) continue;
        const int gx = x + static_cast<int>(k) * 6 * scale;
        for (int r = 0; r < 7; ++r)
            for (int c = 0; c < 5; ++c) {
                if (rows[r * 5 + c] != '#') continue;
                for (int dy = 0; dy < scale; ++dy)
                    for (int dx = 0; dx < scale; ++dx) {
                        int px = gx + c * scale + dx, py = y + r * scale + dy;
                        if (px < 0 || py < 0 || px >= image.width || py >= image.height) continue;
                        uint8_t* p = image.at(px, py);
                        p[0] = color.r, p[1] = color.g, p[2] = color.b;
                    }
            }
    }
}

Image8 montage(const std::vector<std::vector<Image8>>& rows,
               const std::vector<std::vector<std::string>>& labels, int scale) {
    if (rows.empty() || rows[0].empty()) throw InputError("montage: no images");
    int tw = 0, cols = 0;
    for (const auto& row : rows) {
        cols = std::max(cols, static_cast<int>(row.size()));
        for (const Image8& t : row) tw = std::max(tw, t.width);
    }
    const int gap = 4, band = 7 * scale + 6;
    std::vector<int> rowH;
    for (const auto& row : rows) {
        int h = 0;
        for (const Image8& t : row) h = std::max(h, t.height);
        rowH.push_back(h);
    }
    int H = gap;
    for (int h : rowH) H += band + h + gap;
    Image8 out;
    out.resize(gap + cols * (tw + gap), H, 24);
    int y = gap;
    for (size_t r = 0; r < rows.size(); ++r) {
        for (size_t c = 0; c < rows[r].size(); ++c) {
            const Image8& t = rows[r][c];
            const int x = gap + static_cast<int>(c) * (tw + gap);
            if (r < labels.size() && c < labels[r].size()) {
                // Shrink a label that would not fit its tile.
                const int len = std::max<int>(1, static_cast<int>(labels[r][c].size()));
                const int s = std::max(1, std::min(scale, (tw - 4) / (6 * len)));
                drawText(out, x + 2, y + 3 + (7 * scale - 7 * s) / 2, labels[r][c], {240, 240, 240}, s);
            }
            for (int ty = 0; ty < t.height; ++ty)
                std::copy_n(&t.rgb[static_cast<size_t>(ty) * t.width * 3], t.width * 3,
                            out.at(x, y + band + ty));
        }
        y += band + rowH[r] + gap;
    }
    return out;
}

void writePng8(const std::string& path, const Image8& image) {
    writePngRgb8(path, image.width, image.height, image.rgb.data());
}

double meanAbsToneMappedDifference(const std::vector<float>& a, const std::vector<float>& b,
                                   float exposure) {
    if (a.size() != b.size() || a.size() % 4 != 0)
        throw std::invalid_argument("meanAbsToneMappedDifference: the frames differ in size");
    double sum = 0;
    const size_t n = a.size() / 4;
    for (size_t i = 0; i < n; ++i) {
        const glm::vec3 x = toneMapAces(glm::vec3(a[4 * i], a[4 * i + 1], a[4 * i + 2]), exposure);
        const glm::vec3 y = toneMapAces(glm::vec3(b[4 * i], b[4 * i + 1], b[4 * i + 2]), exposure);
        sum += std::abs(x.r - y.r) + std::abs(x.g - y.g) + std::abs(x.b - y.b);
    }
    return sum / (3.0 * std::max<size_t>(1, n));
}

}  // namespace shrefract
