#include "common/prefilter.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>
#include <vector>

#include "common/error.h"
#include "common/frame.h"

namespace shrefract {

namespace {
constexpr float kPi = 3.14159265358979f;

// body(i) for i in [0, n) on all cores. std::thread rather than TBB: the runtime library carries
// this file, and its link interface stays free of TBB (docs/runtime.md "Install").
template <typename Body>
void parallelFor(int n, const Body& body) {
    const int threads = std::max(1, std::min<int>(n, int(std::thread::hardware_concurrency())));
    std::atomic<int> next{0};
    auto work = [&] {
        for (int i = next++; i < n; i = next++) body(i);
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
}
}  // namespace

float PrefilteredCube::sigma(int level) const {
    if (level <= 0 || levels.empty()) return 0.0f;
    return 0.5f * kPi / float(levels[size_t(level)].faceSize);
}

PrefilteredCube prefilterCube(const CubeMapImage& base, int samples) {
    SHREFRACT_CHECK(base.faceSize >= 1 && samples >= 1);
    PrefilteredCube out;
    out.levels.push_back(base);
    // The lobe's points once, around +z: vMF sampling cos(theta) = 1 + ln(1 - u (1 - e^-2k)) / k
    // with stratified u and a golden-angle phi, then rotated into each texel's frame.
    for (int n = base.faceSize / 2, level = 1; n >= 1; n /= 2, ++level) {
        CubeMapImage dst;
        dst.faceSize = n;
        out.levels.push_back(dst);  // sigma(level) needs the face size in place
        const CubeMapImage& src = out.levels[size_t(level - 1)];
        const float s0 = out.sigma(level - 1);
        const float s1 = out.sigma(level);
        const float inc = std::sqrt(std::max(s1 * s1 - s0 * s0, 1e-12f));
        const float kappa = 1.0f / (inc * inc);
        std::vector<glm::vec3> lobe(samples);
        for (int i = 0; i < samples; ++i) {
            const float u = (i + 0.5f) / samples;
            const float c = 1.0f + std::log1p(-u * (1.0f - std::exp(-2.0f * kappa))) / kappa;
            const float sn = std::sqrt(std::max(0.0f, 1.0f - c * c)), phi = 2.39996323f * i;
            lobe[i] = {sn * std::cos(phi), sn * std::sin(phi), std::clamp(c, -1.0f, 1.0f)};
        }
        CubeMapImage& d = out.levels.back();
        for (int f = 0; f < 6; ++f) d.faces[f].assign(size_t(n) * n * 3, 0.0f);
        parallelFor(6 * n, [&](int row) {
            const int f = row / n, y = row % n;
            for (int x = 0; x < n; ++x) {
                const glm::vec3 dir = glm::normalize(
                    cubeFaceDirection(f, 2.0f * (x + 0.5f) / n - 1.0f, 2.0f * (y + 0.5f) / n - 1.0f));
                const Frame frame = Frame::fromNormal(dir);
                glm::vec3 sum(0.0f);
                for (const glm::vec3& p : lobe) sum += sampleCube(src, frame.fromLocal(p));
                sum /= float(samples);
                float* o = &d.faces[f][(size_t(y) * n + x) * 3];
                o[0] = sum.r, o[1] = sum.g, o[2] = sum.b;
            }
        });
    }
    return out;
}

float lodForSigma(float sigma, int faceSize, int levels) {
    const float sigma1 = kPi / float(faceSize);  // (pi / 2) / (faceSize / 2)
    const float lod = sigma <= sigma1 ? sigma / sigma1 : 1.0f + std::log2(sigma / sigma1);
    return std::clamp(lod, 0.0f, float(levels - 1));
}

glm::vec3 sampleCubeLod(const PrefilteredCube& cube, glm::vec3 d, float lod) {
    const int top = int(cube.levels.size()) - 1;
    lod = std::clamp(lod, 0.0f, float(top));
    const int l0 = int(std::floor(lod)), l1 = std::min(l0 + 1, top);
    const float t = lod - float(l0);
    const glm::vec3 a = sampleCube(cube.levels[size_t(l0)], d);
    return t > 0.0f ? glm::mix(a, sampleCube(cube.levels[size_t(l1)], d), t) : a;
}

float spreadSigma(float resultant, float scale) {
    const float r = std::clamp(resultant, 1e-4f, 1.0f);
    if (r >= 1.0f) return 0.0f;
    const float kappa = r * (3.0f - r * r) / (1.0f - r * r);
    return scale / std::sqrt(kappa);
}

float resultantOfSigma(float sigma) {
    if (sigma < 1e-3f) return 1.0f;
    const double kappa = 1.0 / (double(sigma) * sigma), e = std::exp(-2.0 * kappa);
    return float((1.0 + e) / (1.0 - e) - 1.0 / kappa);
}

}  // namespace shrefract
