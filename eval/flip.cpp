#include "eval/flip.h"

#include <algorithm>
#include <string>

#include "common/error.h"

namespace shrefract {

namespace {

using Plane = std::vector<float>;

// The contrast sensitivity functions as spatial filters (the paper's sums of Gaussians): each
// term is a sqrt(pi / b) exp(-pi^2 x^2 / b) with x in degrees from the centre, per opponent
// channel: achromatic, red-green, blue-yellow (a = 0: the first two are single Gaussians).
struct CsfTerm {
    float a, b;
};
constexpr CsfTerm kCsfA[2] = {{1.0f, 0.0047f}, {0.0f, 1e-5f}};
constexpr CsfTerm kCsfRg[2] = {{1.0f, 0.0053f}, {0.0f, 1e-5f}};
constexpr CsfTerm kCsfBy[2] = {{34.1f, 0.04f}, {13.5f, 0.025f}};
// The widest term sets one radius for all channels: 3 standard deviations, sqrt(b / 2 pi^2) degrees.
constexpr float kCsfMaxB = 0.04f;

constexpr float kFeatureWidth = 0.082f;  // degrees: the feature detectors' w
constexpr float kQc = 0.7f, kQf = 0.5f;  // exponents of the colour and feature differences
constexpr float kPc = 0.4f, kPt = 0.95f;  // the colour compression's knee: p_c of the range to p_t

// A 1D kernel, taps[0] at offset -radius, and the sum its taps have in exact arithmetic (1 for a
// smoothing kernel, 0 for a derivative).
struct Kernel {
    std::vector<float> taps;
    float sum;
    int radius() const { return static_cast<int>(taps.size()) / 2; }
};

// One pass along x or y, clamp to edge. Written as sum * I(x) + sum_k w_k (I(x + k) - I(x)), which
// is sum_k w_k I(x + k) when the taps sum to `sum`: a constant image then comes out exactly as the
// constant (smoothing) or exactly 0 (derivatives) instead of off by rounding, so identical images
// give exactly 0 and flat ones exactly their colour difference.
Plane convolve(const Plane& in, int w, int h, const Kernel& k, bool vertical) {
    Plane out(in.size());
    const int r = k.radius();
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = static_cast<size_t>(y) * w + x;
            float s = 0.0f;
            for (int j = -r; j <= r; ++j) {
                const int xx = vertical ? x : std::clamp(x + j, 0, w - 1);
                const int yy = vertical ? std::clamp(y + j, 0, h - 1) : y;
                s += k.taps[j + r] * (in[static_cast<size_t>(yy) * w + xx] - in[i]);
            }
            out[i] = k.sum * in[i] + s;
        }
    return out;
}

// The CSF filter of one opponent channel. Each term is separable, so the normalized 2D filter
// sum_t a_t sqrt(pi / b_t) e_t(x) e_t(y) / total is applied as, per term, two 1D passes of
// e_t / sum(e_t) weighted by the term's share of the 2D filter's sum.
Plane csfFilter(const Plane& in, int w, int h, const CsfTerm (&terms)[2], float ppd) {
    const int r = static_cast<int>(std::ceil(3.0 * std::sqrt(kCsfMaxB / (2.0 * M_PI * M_PI)) * ppd));
    std::vector<Kernel> kernels;
    std::vector<double> shares;
    double total = 0.0;
    for (const CsfTerm& t : terms) {
        if (t.a == 0.0f) continue;
        Kernel k{std::vector<float>(2 * r + 1), 1.0f};
        double s = 0.0;
        for (int j = -r; j <= r; ++j) {
            const double x = j / ppd;  // degrees
            s += k.taps[j + r] = static_cast<float>(std::exp(-M_PI * M_PI * x * x / t.b));
        }
        for (float& v : k.taps) v = static_cast<float>(v / s);
        kernels.push_back(std::move(k));
        shares.push_back(t.a * std::sqrt(M_PI / t.b) * s * s);
        total += shares.back();
    }
    Plane out(in.size(), 0.0f);
    for (size_t t = 0; t < kernels.size(); ++t) {
        const Plane p = convolve(convolve(in, w, h, kernels[t], false), w, h, kernels[t], true);
        const float m = static_cast<float>(shares[t] / total);
        for (size_t i = 0; i < out.size(); ++i) out[i] += m * p[i];
    }
    return out;
}

float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// Linear sRGB (Rec. 709 primaries, D65) to CIE XYZ and back.
glm::vec3 linearRgbToXyz(glm::vec3 c) {
    return {0.4124564f * c.r + 0.3575761f * c.g + 0.1804375f * c.b,
            0.2126729f * c.r + 0.7151522f * c.g + 0.0721750f * c.b,
            0.0193339f * c.r + 0.1191920f * c.g + 0.9503041f * c.b};
}

glm::vec3 xyzToLinearRgb(glm::vec3 x) {
    return {3.2404542f * x.x - 1.5371385f * x.y - 0.4985314f * x.z,
            -0.9692660f * x.x + 1.8760108f * x.y + 0.0415560f * x.z,
            0.0556434f * x.x - 0.2040259f * x.y + 1.0572252f * x.z};
}

// The reference white: RGB (1, 1, 1) through the same matrix, so white maps to L* = 100 exactly.
glm::vec3 whiteXyz() {
    static const glm::vec3 white = linearRgbToXyz(glm::vec3(1.0f));
    return white;
}

// YyCxCz: the opponent space of the CSFs, L*a*b* without the cube roots, so linear in XYZ and
// a filter applied to it is a filter of the light.
glm::vec3 xyzToYcxcz(glm::vec3 xyz) {
    const glm::vec3 n = xyz / whiteXyz();
    return {116.0f * n.y - 16.0f, 500.0f * (n.x - n.y), 200.0f * (n.y - n.z)};
}

glm::vec3 ycxczToXyz(glm::vec3 o) {
    const float y = (o.x + 16.0f) / 116.0f;
    return glm::vec3(y + o.y / 500.0f, y, y - o.z / 200.0f) * whiteXyz();
}

glm::vec3 xyzToLab(glm::vec3 xyz) {
    auto f = [](float t) {
        constexpr float d = 6.0f / 29.0f;
        return t > d * d * d ? std::cbrt(t) : t / (3.0f * d * d) + 4.0f / 29.0f;
    };
    const glm::vec3 n = xyz / whiteXyz();
    const float fx = f(n.x), fy = f(n.y), fz = f(n.z);
    return {116.0f * fy - 16.0f, 500.0f * (fx - fy), 200.0f * (fy - fz)};
}

// The Hunt effect: chroma is seen weaker in the dark, so a* and b* are scaled by L* / 100.
glm::vec3 hunt(glm::vec3 lab) { return {lab.x, 0.01f * lab.x * lab.y, 0.01f * lab.x * lab.z}; }

// HyAB: city-block in lightness, Euclidean in chroma (better than Euclidean L*a*b* for large
// differences).
float hyab(glm::vec3 p, glm::vec3 q) {
    return std::abs(p.x - q.x) + glm::length(glm::vec2(p.y - q.y, p.z - q.z));
}

struct Opponent {
    Plane y, cx, cz;
};

Opponent toOpponent(const std::vector<glm::vec3>& srgb) {
    Opponent o{Plane(srgb.size()), Plane(srgb.size()), Plane(srgb.size())};
    for (size_t i = 0; i < srgb.size(); ++i) {
        const glm::vec3 c = glm::clamp(srgb[i], 0.0f, 1.0f);
        const glm::vec3 v = xyzToYcxcz(
            linearRgbToXyz({srgbToLinear(c.r), srgbToLinear(c.g), srgbToLinear(c.b)}));
        o.y[i] = v.x, o.cx[i] = v.y, o.cz[i] = v.z;
    }
    return o;
}

// The colour pipeline up to the difference: the CSF-filtered opponent channels back to linear
// RGB, clamped to the RGB cube (filtering can leave it), as Hunt-adjusted L*a*b*.
std::vector<glm::vec3> filteredHuntLab(const Opponent& o, int w, int h, float ppd) {
    const Plane y = csfFilter(o.y, w, h, kCsfA, ppd), cx = csfFilter(o.cx, w, h, kCsfRg, ppd),
                cz = csfFilter(o.cz, w, h, kCsfBy, ppd);
    std::vector<glm::vec3> out(y.size());
    for (size_t i = 0; i < out.size(); ++i) {
        const glm::vec3 rgb = glm::clamp(xyzToLinearRgb(ycxczToXyz({y[i], cx[i], cz[i]})), 0.0f, 1.0f);
        out[i] = hunt(xyzToLab(linearRgbToXyz(rgb)));
    }
    return out;
}

// Edge and point strength of the achromatic channel: the magnitudes of the first and second
// derivatives of a Gaussian of sigma 0.5 w ppd along x and y.
struct Features {
    Plane edge, point;
};

Features features(const Opponent& o, int w, int h, float ppd) {
    const float sigma = 0.5f * kFeatureWidth * ppd;
    const int r = static_cast<int>(std::ceil(3.0f * sigma));
    // The 2D detectors are a derivative along one axis times the Gaussian along the other; each
    // is normalized so its positive taps sum to 1 and its negative taps to -1, which for these
    // separable kernels is the same as normalizing the 1D factors so.
    Kernel g{{}, 1.0f}, d1{{}, 0.0f}, d2{{}, 0.0f};
    for (int x = -r; x <= r; ++x) {
        const float e = std::exp(-(x * x) / (2.0f * sigma * sigma));
        g.taps.push_back(e);
        d1.taps.push_back(-x * e);
        d2.taps.push_back((x * x / (sigma * sigma) - 1.0f) * e);
    }
    auto normalize = [](std::vector<float>& taps) {
        float pos = 0.0f, neg = 0.0f;
        for (float v : taps) (v > 0 ? pos : neg) += v;
        for (float& v : taps) v = v > 0 ? v / pos : neg < 0 ? v / -neg : v;
    };
    normalize(g.taps), normalize(d1.taps), normalize(d2.taps);
    // The achromatic channel normalized to [0, 1]: (Yy + 16) / 116, of the unfiltered image.
    Plane a(o.y.size());
    for (size_t i = 0; i < a.size(); ++i) a[i] = (o.y[i] + 16.0f) / 116.0f;
    const Plane ax = convolve(a, w, h, g, false), ay = convolve(a, w, h, g, true);
    const Plane ex = convolve(ay, w, h, d1, false), ey = convolve(ax, w, h, d1, true);
    const Plane px = convolve(ay, w, h, d2, false), py = convolve(ax, w, h, d2, true);
    Features f{Plane(a.size()), Plane(a.size())};
    for (size_t i = 0; i < a.size(); ++i) {
        f.edge[i] = std::hypot(ex[i], ey[i]);
        f.point[i] = std::hypot(px[i], py[i]);
    }
    return f;
}

}  // namespace

std::vector<float> flipMap(const std::vector<glm::vec3>& ref, const std::vector<glm::vec3>& test,
                           int w, int h, float ppd) {
    const size_t n = static_cast<size_t>(std::max(w, 0)) * std::max(h, 0);
    if (ref.size() != n || test.size() != n)
        throw InputError("flipMap: images of " + std::to_string(ref.size()) + " and " +
                         std::to_string(test.size()) + " pixels for " + std::to_string(w) + "x" +
                         std::to_string(h));
    if (!(ppd > 0.0f)) throw InputError("flipMap: pixels per degree " + std::to_string(ppd));
    // The largest colour difference: between the Hunt-adjusted green and blue primaries.
    const float cMax = std::pow(hyab(hunt(xyzToLab(linearRgbToXyz({0, 1, 0}))),
                                     hunt(xyzToLab(linearRgbToXyz({0, 0, 1})))),
                                kQc);
    const Opponent oRef = toOpponent(ref), oTest = toOpponent(test);
    const std::vector<glm::vec3> cRef = filteredHuntLab(oRef, w, h, ppd),
                                 cTest = filteredHuntLab(oTest, w, h, ppd);
    const Features fRef = features(oRef, w, h, ppd), fTest = features(oTest, w, h, ppd);
    std::vector<float> out(n);
    for (size_t i = 0; i < n; ++i) {
        // Colour: the first p_c of [0, cMax] (small differences) onto [0, p_t], the rest onto
        // [p_t, 1].
        const float e = std::pow(hyab(cRef[i], cTest[i]), kQc);
        const float dc = e < kPc * cMax ? kPt / (kPc * cMax) * e
                                        : kPt + (e - kPc * cMax) / (cMax - kPc * cMax) * (1.0f - kPt);
        // Features: each magnitude lies in [0, sqrt 2] (normalized detectors on [0, 1]).
        const float df = std::pow(std::max(std::abs(fRef.edge[i] - fTest.edge[i]),
                                           std::abs(fRef.point[i] - fTest.point[i])) /
                                      std::sqrt(2.0f),
                                  kQf);
        // Colour differences where features differ are pushed up towards 1.
        out[i] = std::pow(dc, 1.0f - df);
    }
    return out;
}

}  // namespace shrefract
