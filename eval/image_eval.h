// Comparing rendered evaluation buffers (common/evalbuffer.h): direction error, coverage, PSNR,
// SSIM and FLIP of the tone-mapped images, error heat maps and labelled montages
// (docs/evaluation.md).
// Needs no Embree; it lives in bake/ beside the other evaluation code.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/evalbuffer.h"

namespace shrefract {

// An 8-bit RGB image, row 0 at the top.
struct Image8 {
    int width = 0, height = 0;
    std::vector<uint8_t> rgb;
    void resize(int w, int h, uint8_t fill = 0) {
        width = w, height = h;
        rgb.assign(static_cast<size_t>(w) * h * 3, fill);
    }
    uint8_t* at(int x, int y) { return &rgb[(static_cast<size_t>(y) * width + x) * 3]; }
};

// Per-pixel angle in degrees between the two direction buffers where both cover the pixel, -1
// elsewhere.
std::vector<float> angularErrors(const EvalBuffer& ref, const EvalBuffer& test);

// The report of `shrefract-eval image`: angleDeg {count, mean, median, p95, p99, max} over the
// pixels both cover; coverage {ref, test, both, refOnly, testOnly, mismatch}; psnr (dB) over
// all pixels and RGB of toneMapAces(colour) in [0, 1]; psnrInterior the same over the object's
// interior pixels (covered by the reference, no coverage change in their 3 x 3 neighbourhood);
// errorShare {silhouette, interior, background}: where the squared error lies (silhouette: the
// reference's coverage changes within the 3 x 3 neighbourhood); ssim: mean SSIM of the tone-mapped
// luminance (Rec. 709 weights), 11x11 Gaussian window sigma 1.5, K1 0.01, K2 0.03, L 1, over
// the windows that lie inside the image. Object metrics, over the pixels the reference covers (the
// object mask), null when it covers none: objectPsnr as psnr; objectSsim, the mean of the same
// SSIM map over the windows centred on object pixels; detailRatio, the mean of |L - G2 * L| (L the
// tone-mapped luminance, G2 a Gaussian of sigma 2 px) of the test over the reference's (1: detail
// kept, < 1 blurred, > 1 noisier; null when the reference has none); objectFlip, the mean LDR-FLIP
// (eval/flip.h) of the tone-mapped images; and flip, its mean over all pixels. Throws InputError
// if the sizes differ.
nlohmann::json compareImages(const EvalBuffer& ref, const EvalBuffer& test, float exposure = 1.0f);

// compareImages for a test that is a display image only (e.g. a browser's frame read back as a
// PNG): its pixels / 255 are taken as the tone-mapped colours and compared with the reference's
// toneMapAces(colour) by the colour keys of compareImages (psnr, psnrInterior, errorShare, ssim,
// objectPsnr, objectSsim, detailRatio, objectFlip, flip), the object mask being the reference's
// coverage; width, height and coverage {ref}. No angleDeg: an image has no exit directions.
// Throws InputError if the sizes differ.
nlohmann::json compareDisplayImage(const EvalBuffer& ref, const Image8& test, float exposure = 1.0f);

// An 8-bit PNG (grey or colour, with or without alpha; the alpha is dropped, not composited) as
// RGB, row 0 at the top. InputError naming the file when it is not a PNG or has 16-bit channels.
Image8 readPng8(const std::string& path);

// Mean SSIM of two single-channel images in [0, 1] (the definition above); exposed for tests.
double ssim(const std::vector<float>& a, const std::vector<float>& b, int width, int height);

// The flicker measure: the mean absolute difference of two RGBA frames' tone-mapped colours (all
// pixels, RGB in [0, 1]), e.g. consecutive frames of a slow orbit (shrefract-render --flicker).
double meanAbsToneMappedDifference(const std::vector<float>& a, const std::vector<float>& b,
                                   float exposure = 1.0f);

// The error colour ramp: 0 degrees dark blue through green and yellow to red at maxDegrees
// (and beyond).
glm::u8vec3 errorColor(float degrees, float maxDegrees);

// Heat map: covered-by-both pixels coloured by errorColor(error, maxDegrees); coverage mismatch
// magenta; background (neither) the reference's tone-mapped colour at a quarter brightness; and a
// legend strip under the image (ramp, "0" ... "30 DEG").
Image8 heatMap(const EvalBuffer& ref, const EvalBuffer& test, float maxDegrees = 30.0f,
               float exposure = 1.0f);

// FLIP heat map: every pixel's LDR-FLIP of the tone-mapped images through errorColor(flip, 1), and
// a legend strip under the image ("0" ... "1 FLIP").
Image8 flipHeatMap(const EvalBuffer& ref, const EvalBuffer& test, float exposure = 1.0f);

// The tone-mapped colour of a buffer.
Image8 toneMapped(const EvalBuffer& buffer, float exposure = 1.0f);

// Side by side, each tile under a label band (built-in 5x7 font, upper case), like the paper's
// Figure 11. `rows` of tiles, all of one size; labels[r][c] for tile c of row r.
Image8 montage(const std::vector<std::vector<Image8>>& rows,
               const std::vector<std::vector<std::string>>& labels, int scale = 2);

// Draws text (upper-cased; unknown characters as blanks) with its top-left at (x, y).
void drawText(Image8& image, int x, int y, const std::string& text, glm::u8vec3 color, int scale);

// Writes an 8-bit sRGB PNG via a temporary name; throws InputError naming the file.
void writePng8(const std::string& path, const Image8& image);

}  // namespace shrefract
