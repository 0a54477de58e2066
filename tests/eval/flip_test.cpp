// LDR-FLIP (eval/flip.h) against answers worked out independently of it: exact zeros, the closed
// form of a flat colour difference, a one-dimensional double-precision twin of the whole
// pipeline, and the order of blurs and shifts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "eval/flip.h"

using namespace shrefract;

namespace {

constexpr int kW = 64, kH = 48;

std::vector<glm::vec3> flat(glm::vec3 c) { return std::vector<glm::vec3>(size_t(kW) * kH, c); }

double mean(const std::vector<float>& v) {
    double s = 0;
    for (float x : v) s += x;
    return s / v.size();
}

// The paper's formulae in double precision, written apart from eval/flip.cpp: sRGB -> linear ->
// XYZ (D65, white = RGB 1) -> YyCxCz or L*a*b* -> Hunt -> HyAB -> the colour compression.
glm::dvec3 linear(glm::dvec3 c) {
    for (int k = 0; k < 3; ++k) c[k] = c[k] <= 0.04045 ? c[k] / 12.92 : std::pow((c[k] + 0.055) / 1.055, 2.4);
    return c;
}

const glm::dmat3 kRgbToXyz = glm::transpose(glm::dmat3(0.4124564, 0.3575761, 0.1804375,  // rows
                                                       0.2126729, 0.7151522, 0.0721750,
                                                       0.0193339, 0.1191920, 0.9503041));
const glm::dvec3 kWhite = kRgbToXyz * glm::dvec3(1.0);

glm::dvec3 huntLab(glm::dvec3 linearRgb) {
    const glm::dvec3 n = kRgbToXyz * linearRgb / kWhite;
    auto f = [](double t) { return t > std::pow(6.0 / 29, 3) ? std::cbrt(t) : t / (3 * std::pow(6.0 / 29, 2)) + 4.0 / 29; };
    const double L = 116 * f(n.y) - 16, a = 500 * (f(n.x) - f(n.y)), b = 200 * (f(n.y) - f(n.z));
    return {L, L / 100 * a, L / 100 * b};
}

double hyab(glm::dvec3 u, glm::dvec3 v) { return std::abs(u.x - v.x) + std::hypot(u.y - v.y, u.z - v.z); }

// The colour term of FLIP from two Hunt-adjusted L*a*b* colours: HyAB^0.7 over that of the green
// and blue primaries, its first 0.4 onto [0, 0.95] and the rest onto [0.95, 1].
double colourTerm(glm::dvec3 p, glm::dvec3 q) {
    const double cMax = std::pow(hyab(huntLab({0, 1, 0}), huntLab({0, 0, 1})), 0.7);
    const double e = std::pow(hyab(p, q), 0.7);
    return e < 0.4 * cMax ? 0.95 * e / (0.4 * cMax) : 0.95 + 0.05 * (e - 0.4 * cMax) / (0.6 * cMax);
}

// FLIP between two flat images: on a constant image the CSF filters (normalized, clamp to edge)
// return the constant and the feature detectors 0, so only the colour term is left.
double flatFlip(glm::dvec3 p, glm::dvec3 q) { return colourTerm(huntLab(linear(p)), huntLab(linear(q))); }

// FLIP of two images that vary along x only (one row given), the whole pipeline in one dimension:
// along y such an image is constant, so each 2D filter reduces to its marginal along x (the CSF
// filter summed over y; the feature detectors' derivative factor, the Gaussian across summing to
// 1, and the derivative across giving 0).
std::vector<double> flipOfColumns(const std::vector<glm::dvec3>& ref, const std::vector<glm::dvec3>& test, double ppd) {
    const int n = int(ref.size());
    auto convolve = [n](const std::vector<double>& in, const std::vector<double>& k) {
        const int r = int(k.size()) / 2;
        std::vector<double> out(n, 0.0);
        for (int x = 0; x < n; ++x)
            for (int j = -r; j <= r; ++j) out[x] += k[j + r] * in[std::clamp(x + j, 0, n - 1)];
        return out;
    };
    // CSF: terms a sqrt(pi / b) exp(-pi^2 (x^2 + y^2) / b), x and y in degrees, radius 3 standard
    // deviations of the widest term (b = 0.04), the marginal normalized to sum 1.
    const int rc = int(std::ceil(3 * std::sqrt(0.04 / (2 * M_PI * M_PI)) * ppd));
    auto csf = [&](std::vector<std::pair<double, double>> terms) {
        std::vector<double> k(2 * rc + 1, 0.0);
        for (auto [a, b] : terms) {
            double across = 0;
            for (int j = -rc; j <= rc; ++j) across += std::exp(-M_PI * M_PI * (j / ppd) * (j / ppd) / b);
            for (int j = -rc; j <= rc; ++j)
                k[j + rc] += a * std::sqrt(M_PI / b) * std::exp(-M_PI * M_PI * (j / ppd) * (j / ppd) / b) * across;
        }
        double sum = 0;
        for (double v : k) sum += v;
        for (double& v : k) v /= sum;
        return k;
    };
    const std::vector<double> kA = csf({{1.0, 0.0047}}), kRg = csf({{1.0, 0.0053}}),
                              kBy = csf({{34.1, 0.04}, {13.5, 0.025}});
    // Features: first and second derivatives of a Gaussian of sigma 0.5 * 0.082 deg, radius 3 sigma,
    // positive taps summing to 1 and negative ones to -1.
    const double sigma = 0.5 * 0.082 * ppd;
    const int rf = int(std::ceil(3 * sigma));
    std::vector<double> d1, d2;
    for (int j = -rf; j <= rf; ++j) {
        const double g = std::exp(-j * j / (2 * sigma * sigma));
        d1.push_back(-j * g), d2.push_back((j * j / (sigma * sigma) - 1) * g);
    }
    for (std::vector<double>* k : {&d1, &d2}) {
        double pos = 0, neg = 0;
        for (double v : *k) (v > 0 ? pos : neg) += v;
        for (double& v : *k) v /= v > 0 ? pos : -neg;
    }
    struct Seen {
        std::vector<glm::dvec3> huntLab;
        std::vector<double> edge, point;
    };
    auto see = [&](const std::vector<glm::dvec3>& srgb) {
        std::vector<double> y(n), cx(n), cz(n), achromatic(n);
        for (int x = 0; x < n; ++x) {
            const glm::dvec3 w = kRgbToXyz * linear(srgb[x]) / kWhite;
            y[x] = 116 * w.y - 16, cx[x] = 500 * (w.x - w.y), cz[x] = 200 * (w.y - w.z);
            achromatic[x] = (y[x] + 16) / 116;
        }
        y = convolve(y, kA), cx = convolve(cx, kRg), cz = convolve(cz, kBy);
        Seen s{std::vector<glm::dvec3>(n), convolve(achromatic, d1), convolve(achromatic, d2)};
        for (int x = 0; x < n; ++x) {
            const double wy = (y[x] + 16) / 116;
            const glm::dvec3 xyz = glm::dvec3(wy + cx[x] / 500, wy, wy - cz[x] / 200) * kWhite;
            s.huntLab[x] = huntLab(glm::clamp(glm::inverse(kRgbToXyz) * xyz, 0.0, 1.0));
        }
        return s;
    };
    const Seen r = see(ref), t = see(test);
    std::vector<double> out(n);
    for (int x = 0; x < n; ++x) {
        const double df = std::sqrt(std::max(std::abs(std::abs(r.edge[x]) - std::abs(t.edge[x])),
                                             std::abs(std::abs(r.point[x]) - std::abs(t.point[x]))) / std::sqrt(2.0));
        out[x] = std::pow(colourTerm(r.huntLab[x], t.huntLab[x]), 1 - df);
    }
    return out;
}

// Separable Gaussian blur, radius 3 sigma, clamp to edge.
std::vector<glm::vec3> blur(const std::vector<glm::vec3>& in, float sigma) {
    const int r = int(std::ceil(3 * sigma));
    std::vector<float> g;
    float sum = 0;
    for (int k = -r; k <= r; ++k) g.push_back(std::exp(-k * k / (2 * sigma * sigma))), sum += g.back();
    std::vector<glm::vec3> rows(in.size()), out(in.size());
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            glm::vec3 s(0);
            for (int k = -r; k <= r; ++k) s += g[k + r] / sum * in[y * kW + std::clamp(x + k, 0, kW - 1)];
            rows[y * kW + x] = s;
        }
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            glm::vec3 s(0);
            for (int k = -r; k <= r; ++k) s += g[k + r] / sum * rows[std::clamp(y + k, 0, kH - 1) * kW + x];
            out[y * kW + x] = s;
        }
    return out;
}

// A colour texture with detail at several scales: white noise blurred with sigma 1 px plus noise
// blurred with sigma 4 px, per channel, around mid grey. Its autocorrelation falls with distance,
// so a larger shift or blur moves it further from itself.
std::vector<glm::vec3> texture(unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> n(0.0f, 1.0f);
    std::vector<glm::vec3> fine(size_t(kW) * kH), coarse(fine.size());
    for (size_t i = 0; i < fine.size(); ++i) fine[i] = {n(rng), n(rng), n(rng)}, coarse[i] = {n(rng), n(rng), n(rng)};
    fine = blur(fine, 1.0f), coarse = blur(coarse, 4.0f);
    std::vector<glm::vec3> t(fine.size());
    for (size_t i = 0; i < t.size(); ++i) t[i] = glm::clamp(0.5f + 0.6f * fine[i] + 2.5f * coarse[i], 0.0f, 1.0f);
    return t;
}

// The image moved `s` pixels to the right, its left column repeated.
std::vector<glm::vec3> shift(const std::vector<glm::vec3>& in, int s) {
    std::vector<glm::vec3> out(in.size());
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) out[y * kW + x] = in[y * kW + std::max(0, x - s)];
    return out;
}

}  // namespace

TEST(Flip, PixelsPerDegreeOfThePapersMonitor) {
    EXPECT_NEAR(pixelsPerDegree(), 3840 * M_PI / 180, 1e-4);  // 67.02
    EXPECT_NEAR(pixelsPerDegree(0.7f, 0.7f, 1920.0f), 3840 * M_PI / 180 / 2, 1e-4);
}

TEST(Flip, IdenticalImagesGiveExactlyZero) {
    const std::vector<glm::vec3> t = texture(1);
    for (float v : flipMap(t, t, kW, kH)) ASSERT_EQ(v, 0.0f);
    for (float v : flipMap(flat({0.3f, 0.6f, 0.9f}), flat({0.3f, 0.6f, 0.9f}), kW, kH)) ASSERT_EQ(v, 0.0f);
}

// Tolerance 1e-4: flipMap runs in float. Each colour-space step loses about 1e-7 relative, and the
// 7-digit XYZ matrices invert each other only to about 1e-7, so HyAB (tens of units) comes out
// within about 1e-5 relative, and so does FLIP after the 0.7 power and the linear compression.
// A wrong constant (a matrix entry, the Hunt factor, p_c, the white) moves it by 1e-3 or more.
TEST(Flip, FlatColourDifferenceMatchesTheClosedForm) {
    struct Pair {
        glm::vec3 a, b;
    };
    // Two below the compression's knee (FLIP 0.95), one above it, and the largest difference
    // (green and blue: 1).
    for (const Pair& p : {Pair{{0.5f, 0.4f, 0.3f}, {0.45f, 0.42f, 0.33f}},
                          Pair{{0.8f, 0.3f, 0.2f}, {0.25f, 0.55f, 0.7f}},
                          Pair{{0.9f, 0.9f, 0.1f}, {0.1f, 0.1f, 0.8f}},
                          Pair{{0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 1.0f}}}) {
        const double expected = flatFlip(p.a, p.b);
        const std::vector<float> m = flipMap(flat(p.a), flat(p.b), kW, kH);
        std::printf("[ measured ] flat (%g %g %g) vs (%g %g %g): closed form %.7f, flipMap %.7f (%.1e)\n",
                    p.a.r, p.a.g, p.a.b, p.b.r, p.b.g, p.b.b, expected, m[0], m[0] - expected);
        for (float v : m) ASSERT_NEAR(v, expected, 1e-5);
    }
    EXPECT_NEAR(flatFlip({0, 1, 0}, {0, 0, 1}), 1.0, 1e-12);
}

// Images constant along y against flipOfColumns: piecewise-constant colour runs of 1 to 8 pixels,
// half of them RGB cube corners (edges and points for the detectors, chroma changes for the CSFs), the test's left half moved
// one pixel and its right half recoloured slightly. Tolerance 1e-4: float against double (measured
// 1.4e-6); where the feature difference is near 0 its square root magnifies rounding (1e-9 into
// 3e-5), while a wrong kernel, normalization or exponent moves FLIP by 1e-2 or more.
TEST(Flip, ImagesAlongXMatchTheOneDimensionalTwin) {
    std::mt19937 rng(6);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<glm::dvec3> ref, test;
    while (ref.size() < size_t(kW)) {
        glm::dvec3 c(u(rng), u(rng), u(rng));
        if (u(rng) < 0.5) c = glm::round(c);  // saturated: filtering leaves the RGB cube near their edges
        for (int k = 1 + int(u(rng) * 8); k > 0 && ref.size() < size_t(kW); --k) ref.push_back(c);
    }
    for (int x = 0; x < kW; ++x)
        test.push_back(x < kW / 2 ? ref[std::max(0, x - 1)]
                                  : glm::clamp(ref[x] + 0.05 * glm::dvec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5), 0.0, 1.0));
    for (int x = 0; x < kW; ++x) ref[x] = glm::dvec3(glm::vec3(ref[x])), test[x] = glm::dvec3(glm::vec3(test[x]));
    std::vector<glm::vec3> a, b;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) a.emplace_back(ref[x]), b.emplace_back(test[x]);
    const std::vector<float> m = flipMap(a, b, kW, kH);
    const std::vector<double> expected = flipOfColumns(ref, test, pixelsPerDegree());
    double worst = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            worst = std::max(worst, std::abs(m[y * kW + x] - expected[x]));
            ASSERT_NEAR(m[y * kW + x], expected[x], 1e-4) << "x " << x << " y " << y;
        }
    std::printf("[ measured ] mean FLIP %.4f, largest difference from the twin %.1e\n", mean(m), worst);
}

TEST(Flip, FlatImagesAreSymmetric) {
    const glm::vec3 a(0.9f, 0.2f, 0.4f), b(0.1f, 0.7f, 0.3f);
    EXPECT_EQ(flipMap(flat(a), flat(b), kW, kH), flipMap(flat(b), flat(a), kW, kH));
}

TEST(Flip, LiesInZeroToOneAndIsSymmetricOnNoise) {
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<glm::vec3> a(size_t(kW) * kH), b(a.size());
    for (size_t i = 0; i < a.size(); ++i) {
        a[i] = {u(rng), u(rng), u(rng)};
        b[i] = glm::round(glm::vec3(u(rng), u(rng), u(rng)));  // the RGB cube's corners
    }
    const std::vector<float> m = flipMap(a, b, kW, kH);
    EXPECT_EQ(m, flipMap(b, a, kW, kH));
    for (float v : m) {
        ASSERT_GE(v, 0.0f);
        ASSERT_LE(v, 1.0f);
    }
    EXPECT_GT(mean(m), 0.3);
}

TEST(Flip, RisesWithBlur) {
    const std::vector<glm::vec3> t = texture(2);
    double last = 0;
    for (float sigma : {0.5f, 1.0f, 2.0f}) {
        const double f = mean(flipMap(t, blur(t, sigma), kW, kH));
        std::printf("[ measured ] blur sigma %.1f px: mean FLIP %.4f\n", sigma, f);
        EXPECT_GT(f, last) << "sigma " << sigma;
        last = f;
    }
}

TEST(Flip, RisesWithShift) {
    const std::vector<glm::vec3> t = texture(3);
    double last = 0;
    for (int s : {1, 2, 4}) {
        const double f = mean(flipMap(t, shift(t, s), kW, kH));
        std::printf("[ measured ] shift %d px: mean FLIP %.4f\n", s, f);
        EXPECT_GT(f, last) << "shift " << s;
        last = f;
    }
}

// The pipeline treats x and y alike: transposed images give the transposed map (up to the order
// of the separable passes' rounding, which the feature term's square root can magnify to ~1e-5).
TEST(Flip, CommutesWithTransposition) {
    const std::vector<glm::vec3> a = texture(7), b = blur(shift(texture(7), 1), 0.7f);
    std::vector<glm::vec3> at(a.size()), bt(b.size());
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) at[x * kH + y] = a[y * kW + x], bt[x * kH + y] = b[y * kW + x];
    const std::vector<float> m = flipMap(a, b, kW, kH), mt = flipMap(at, bt, kH, kW);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) ASSERT_NEAR(m[y * kW + x], mt[x * kH + y], 1e-4) << "x " << x << " y " << y;
}

TEST(Flip, RefusesMismatchedSizes) {
    EXPECT_THROW(flipMap(flat({0, 0, 0}), flat({0, 0, 0}), kW + 1, kH), std::runtime_error);
    EXPECT_THROW(flipMap(flat({0, 0, 0}), flat({0, 0, 0}), kW, kH, 0.0f), std::runtime_error);
}
