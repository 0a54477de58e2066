// 8-bit weights: value = scale * code + offset, per coefficient k and channel c. The scale and
// offset of each are fitted to the weights' range and kept in the manifest ("u8"); the weights
// part holds the codes, four channels packed in one UINT (weight_parts.cpp).
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Imath/half.h>

#include "common/format_internal.h"

namespace shrefract::format_internal {

// Scale and offset are kept in double precision (the manifest stores them as JSON numbers) and
// the decode rounds to float once, so that code 0 gives the minimum and code 255 the maximum
// exactly. (With a float scale lo + 255 * scale lands on a grid about two float ulps apart and
// often misses the maximum.)
float dequantU8(double scale, double offset, uint32_t code) {
    return static_cast<float>(scale * double(code) + offset);
}

namespace {

// (hi - lo) / 255, nudged by a few double ulps should code 255 not decode to hi exactly.
double fitScale(float lo, float hi) {
    if (!(hi > lo)) return 0.0;  // constant channel: every code decodes to lo
    const double s = (double(hi) - double(lo)) / 255.0;
    double up = s, down = s;
    for (int step = 0; step < 16; ++step) {
        if (dequantU8(up, lo, 255) == hi) return up;
        if (dequantU8(down, lo, 255) == hi) return down;
        up = std::nextafter(up, INFINITY);
        down = std::nextafter(down, 0.0);
    }
    return s;
}

}  // namespace

uint32_t quantU8(float v, double scale, double offset) {
    if (scale == 0.0) return 0;
    const double code = std::nearbyint((double(v) - offset) / scale);
    return static_cast<uint32_t>(std::clamp(code, 0.0, 255.0));
}

U8Params fitU8(const BakeData& d) {
    const int K = d.coefficientCount();
    const size_t N = d.layout.position.size();
    U8Params q;
    q.scale.assign(size_t(K) * 4, 0.0);
    q.offset.assign(size_t(K) * 4, 0.0);
    for (int k = 0; k < K; ++k) {
        for (int c = 0; c < 4; ++c) {
            float lo = INFINITY, hi = -INFINITY;
            for (size_t i = 0; i < N; ++i) {
                const float v = d.weights[(size_t(k) * N + i) * 4 + c];
                if (!std::isfinite(v)) {
                    throw std::invalid_argument("writeBake: weight " + std::to_string(k) +
                                                " of sample " + std::to_string(i) + " channel " +
                                                kWeightSuffix[c] + " is not finite");
                }
                lo = std::min(lo, v);
                hi = std::max(hi, v);
            }
            if (N == 0) lo = hi = 0.0f;
            q.offset[k * 4 + c] = lo;
            q.scale[k * 4 + c] = fitScale(lo, hi);
        }
    }
    return q;
}

}  // namespace shrefract::format_internal

namespace shrefract {

void quantizeWeights(BakeData& d) {
    if (d.precision == Precision::F16) {
        for (float& w : d.weights) w = float(Imath::half(w));
    } else if (d.precision == Precision::U8) {
        const format_internal::U8Params q = format_internal::fitU8(d);
        const size_t N = d.layout.position.size();
        for (size_t j = 0; j < d.weights.size(); ++j) {
            const size_t kc = (j / (N * 4)) * 4 + j % 4;  // weights[(k * N + i) * 4 + c]
            d.weights[j] = format_internal::dequantU8(
                q.scale[kc], q.offset[kc], format_internal::quantU8(d.weights[j], q.scale[kc], q.offset[kc]));
        }
        d.u8Scale.assign(q.scale.begin(), q.scale.end());
        d.u8Offset.assign(q.offset.begin(), q.offset.end());
    }
}

}  // namespace shrefract
