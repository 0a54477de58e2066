// Real spherical harmonics: exact Cartesian polynomials, the double-precision Legendre
// recurrence (reference) and the float fast path. Conventions: docs/conventions.md.
//
// Real SH without the Condon-Shortley phase, orthonormal on the unit sphere:
//   y_l^0  = K_l^0 P_l^0(cos theta)
//   y_l^m  = sqrt2 K_l^m P_l^m(cos theta) cos(m phi)          m > 0
//   y_l^m  = sqrt2 K_l^|m| P_l^|m|(cos theta) sin(|m| phi)    m < 0
//   K_l^m  = sqrt((2l+1)/(4 pi) (l-m)!/(l+m)!),  P_l^m(z) = (1-z^2)^(m/2) d^m/dz^m P_l(z).
#include "common/sh.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>
#include <tuple>

#include "common/error.h"

namespace shrefract {

namespace {

using i128 = __int128;

constexpr long double kPiL = 3.141592653589793238462643383279502884L;
constexpr double kPi = 3.14159265358979323846;

i128 mulChecked(i128 a, i128 b) {
    i128 r;
    SHREFRACT_CHECK(!__builtin_mul_overflow(a, b, &r));
    return r;
}

i128 addChecked(i128 a, i128 b) {
    i128 r;
    SHREFRACT_CHECK(!__builtin_add_overflow(a, b, &r));
    return r;
}

// C(n, k) exactly: r_{i+1} = r_i (n - i) / (i + 1) is C(n, i+1), an integer at every step.
i128 binomial(int n, int k) {
    if (k < 0 || k > n) return 0;
    i128 r = 1;
    for (int i = 0; i < k; ++i) r = mulChecked(r, n - i) / (i + 1);
    return r;
}

// n! / (n - k)!
i128 fallingFactorial(int n, int k) {
    i128 r = 1;
    for (int i = 0; i < k; ++i) r = mulChecked(r, n - i);
    return r;
}

i128 abs128(i128 a) { return a < 0 ? -a : a; }

i128 gcd128(i128 a, i128 b) {
    a = abs128(a);
    b = abs128(b);
    while (b != 0) {
        i128 t = a % b;
        a = b;
        b = t;
    }
    return a;
}

// Coefficients of the normalized associated Legendre recurrence, Pbar = K P (no CS phase):
//   Pbar_m^m     = sqrt((2m+1)/(2m)) s Pbar_{m-1}^{m-1},   Pbar_0^0 = 1/sqrt(4 pi)
//   Pbar_{m+1}^m = sqrt(2m+3) z Pbar_m^m
//   Pbar_l^m     = a_l^m (z Pbar_{l-1}^m - b_l^m Pbar_{l-2}^m),
//   a_l^m = sqrt((4l^2-1)/(l^2-m^2)),  b_l^m = sqrt(((l-1)^2-m^2)/(4(l-1)^2-1)).
// (From (l-m) P_l^m = (2l-1) z P_{l-1}^m - (l+m-1) P_{l-2}^m after multiplying by K_l^m.)
double recA(int l, int m) {
    return std::sqrt((4.0 * l * l - 1.0) / (double(l) * l - double(m) * m));
}
double recB(int l, int m) {
    return std::sqrt((double(l - 1) * (l - 1) - double(m) * m) / (4.0 * (l - 1) * (l - 1) - 1.0));
}

// Pbar_l^m(z) for all l = m..L at one m; `pmm` is Pbar_m^m (already holds s^m). out[l - m].
void legendreColumn(int L, int m, double z, double pmm, double* out) {
    out[0] = pmm;
    if (L == m) return;
    out[1] = std::sqrt(2.0 * m + 3.0) * z * pmm;
    for (int l = m + 2; l <= L; ++l)
        out[l - m] = recA(l, m) * (z * out[l - 1 - m] - recB(l, m) * out[l - 2 - m]);
}

// Float tables for shEvalEven: a_l^m, b_l^m and Pbar_m^m / s^m, through kMaxFastOrder.
constexpr int kMaxFastOrder = 64;
struct FastTables {
    float a[kMaxFastOrder + 1][kMaxFastOrder + 1];
    float b[kMaxFastOrder + 1][kMaxFastOrder + 1];
    float pmm[kMaxFastOrder + 1];  // Pbar_m^m / s^m
    float amp[kMaxFastOrder + 1];  // sqrt(2m+3)
};
const FastTables& fastTables() {
    static const FastTables* tables = [] {
        auto* t = new FastTables();
        double p = 1.0 / std::sqrt(4.0 * kPi);
        for (int m = 0; m <= kMaxFastOrder; ++m) {
            if (m > 0) p *= std::sqrt((2.0 * m + 1.0) / (2.0 * m));
            t->pmm[m] = float(p);
            t->amp[m] = float(std::sqrt(2.0 * m + 3.0));
            for (int l = 0; l <= kMaxFastOrder; ++l) {
                t->a[l][m] = l >= m + 2 ? float(recA(l, m)) : 0.0f;
                t->b[l][m] = l >= m + 2 ? float(recB(l, m)) : 0.0f;
            }
        }
        return t;
    }();
    return *tables;
}

}  // namespace

std::vector<ShLM> shEvenFunctions(int L) {
    std::vector<ShLM> f;
    f.reserve(shEvenCount(L));
    for (int l = 0; l <= L; ++l)
        for (int m = -l; m <= l; m += 2) f.push_back({l, m});
    return f;
}

double shEvalRecurrence(int l, int m, glm::dvec3 w) {
    SHREFRACT_CHECK(l >= 0 && std::abs(m) <= l);
    w = glm::normalize(w);
    int am = std::abs(m);
    double s = std::hypot(w.x, w.y);
    double phi = std::atan2(w.y, w.x);
    double pmm = 1.0 / std::sqrt(4.0 * kPi);
    for (int k = 1; k <= am; ++k) pmm *= std::sqrt((2.0 * k + 1.0) / (2.0 * k)) * s;
    std::vector<double> col(l - am + 1);
    legendreColumn(l, am, w.z, pmm, col.data());
    double p = col[l - am];
    if (m == 0) return p;
    return std::sqrt(2.0) * p * (m > 0 ? std::cos(am * phi) : std::sin(am * phi));
}

void shEvalAllRecurrence(int L, glm::dvec3 w, double* out) {
    SHREFRACT_CHECK(L >= 0);
    w = glm::normalize(w);
    double s = std::hypot(w.x, w.y);
    double phi = std::atan2(w.y, w.x);
    std::vector<double> col(L + 1);
    double pmm = 1.0 / std::sqrt(4.0 * kPi);
    for (int m = 0; m <= L; ++m) {
        if (m > 0) pmm *= std::sqrt((2.0 * m + 1.0) / (2.0 * m)) * s;
        legendreColumn(L, m, w.z, pmm, col.data());
        double c = std::sqrt(2.0) * std::cos(m * phi), sn = std::sqrt(2.0) * std::sin(m * phi);
        for (int l = m; l <= L; ++l) {
            if (m == 0) {
                out[shIndex(l, 0)] = col[l];
            } else {
                out[shIndex(l, m)] = col[l - m] * c;
                out[shIndex(l, -m)] = col[l - m] * sn;
            }
        }
    }
}

void shEvalEven(int L, glm::vec3 w, float* out) {
    SHREFRACT_CHECK(L >= 0 && L <= kMaxFastOrder);
    const FastTables& t = fastTables();
    // No trigonometry: s^m cos(m phi) = Re (x+iy)^m, s^m sin(m phi) = Im (x+iy)^m, and the
    // recurrence is linear, so it runs on Q_l^m = Pbar_l^m / s^m (a polynomial in z).
    float q[kMaxFastOrder + 1];
    float re = 1.0f, im = 0.0f;  // (x + iy)^m
    const float sqrt2 = 1.41421356237309515f;
    for (int m = 0; m <= L; ++m) {
        if (m > 0) {
            float r = re * w.x - im * w.y;
            im = re * w.y + im * w.x;
            re = r;
        }
        q[m] = t.pmm[m];
        if (m < L) q[m + 1] = t.amp[m] * w.z * q[m];
        for (int l = m + 2; l <= L; ++l) q[l] = t.a[l][m] * (w.z * q[l - 1] - t.b[l][m] * q[l - 2]);
        // Even parity: l = m, m+2, ...
        float c = sqrt2 * re, sn = sqrt2 * im;
        for (int l = m; l <= L; l += 2) {
            if (m == 0) {
                out[shEvenIndex(l, 0)] = q[l];
            } else {
                out[shEvenIndex(l, m)] = q[l] * c;
                out[shEvenIndex(l, -m)] = q[l] * sn;
            }
        }
    }
}

double ShPolynomial::absSum() const {
    double sum = 0.0;
    for (const Monomial& t : terms) sum += std::fabs(double(t.num) * scale);
    return sum;
}

double ShPolynomial::eval(glm::dvec3 w) const {
    int n = 0;
    for (const Monomial& t : terms) n = std::max({n, t.a, t.b, t.c});
    std::vector<double> px(n + 1), py(n + 1), pz(n + 1);
    px[0] = py[0] = pz[0] = 1.0;
    for (int i = 1; i <= n; ++i) {
        px[i] = px[i - 1] * w.x;
        py[i] = py[i - 1] * w.y;
        pz[i] = pz[i - 1] * w.z;
    }
    double sum = 0.0;
    for (const Monomial& t : terms) sum += double(t.num) * px[t.a] * py[t.b] * pz[t.c];
    return sum * scale;
}

std::string ShPolynomial::ToString() const {
    std::ostringstream os;
    os.precision(17);
    os << "y_" << l << "^" << m << " = " << scale << " * (";
    bool first = true;
    for (const Monomial& t : terms) {
        int64_t mag = t.num < 0 ? -t.num : t.num;
        os << (first ? (t.num < 0 ? "-" : "") : (t.num < 0 ? " - " : " + "));
        first = false;
        bool constant = t.a == 0 && t.b == 0 && t.c == 0;
        if (mag != 1 || constant) os << mag;
        const char* sep = (mag != 1 || constant) ? " " : "";
        auto var = [&](const char* v, int p) {
            if (p == 0) return;
            os << sep << v;
            if (p > 1) os << "^" << p;
            sep = " ";
        };
        var("x", t.a);
        var("y", t.b);
        var("z", t.c);
    }
    os << ")";
    return os.str();
}

ShPolynomial shPolynomial(int l, int m) {
    SHREFRACT_CHECK(l >= 0 && std::abs(m) <= l);
    const int am = std::abs(m);

    // Legendre part. P_l(z) = 2^-l sum_k (-1)^k C(l,k) C(2l-2k,l) z^(l-2k), so
    //   2^l d^m/dz^m P_l(z) = sum_{k: l-2k >= m} c_k z^(l-2k-m),
    //   c_k = (-1)^k C(l,k) C(2l-2k,l) (l-2k)! / (l-2k-m)!.
    std::vector<std::pair<int, i128>> zTerms;  // (power of z, c_k)
    for (int k = 0; l - 2 * k - am >= 0; ++k) {
        i128 c = mulChecked(binomial(l, k), binomial(2 * l - 2 * k, l));
        c = mulChecked(c, fallingFactorial(l - 2 * k, am));
        zTerms.push_back({l - 2 * k - am, (k & 1) ? -c : c});
    }

    // Azimuthal part. On the unit sphere (1-z^2)^(m/2) e^(i m phi) = (x + iy)^m, and
    //   (x + iy)^m = sum_j C(m,j) x^(m-j) (iy)^j,  i^j = (-1)^(j/2) (j even), i (-1)^(j/2) (j odd):
    // cos (m > 0, m = 0) takes the real part (j even), sin (m < 0) the imaginary part (j odd).
    std::vector<std::tuple<int, int, i128>> xyTerms;  // (power of x, power of y, coefficient)
    for (int j = (m < 0 ? 1 : 0); j <= am; j += 2) {
        i128 c = binomial(am, j);
        xyTerms.push_back({am - j, j, ((j / 2) & 1) ? -c : c});
    }

    // Product, merging equal monomials (x^a y^b z^c), then the common factor g goes to `scale`.
    std::map<std::tuple<int, int, int>, i128, std::greater<>> merged;
    for (const auto& [a, b, cxy] : xyTerms)
        for (const auto& [c, cz] : zTerms) {
            i128& slot = merged[{a, b, c}];
            slot = addChecked(slot, mulChecked(cxy, cz));
        }
    i128 g = 0;
    for (const auto& kv : merged) g = gcd128(g, kv.second);
    SHREFRACT_CHECK(g > 0);

    ShPolynomial p;
    p.l = l;
    p.m = m;
    for (const auto& [key, c] : merged) {
        if (c == 0) continue;
        i128 n = c / g;
        SHREFRACT_CHECK(n >= INT64_MIN && n <= INT64_MAX);  // exact numerators must fit int64
        p.terms.push_back({std::get<0>(key), std::get<1>(key), std::get<2>(key), int64_t(n)});
    }

    // scale = g / 2^l * sqrt((2 - delta_m0) (2l+1) / (4 pi) * (l-|m|)! / (l+|m|)!),
    // the only rounded number: computed in long double, rounded once to double.
    long double ratio = 1.0L;  // (l-|m|)! / (l+|m|)!
    for (int i = l - am + 1; i <= l + am; ++i) ratio /= (long double)i;
    long double k2 = (m == 0 ? 1.0L : 2.0L) * (2.0L * l + 1.0L) / (4.0L * kPiL) * ratio;
    long double gl = (long double)g;  // exact below 2^64
    p.scale = double(gl * std::sqrt(k2) / std::ldexp(1.0L, l));
    return p;
}

std::vector<double> shBandFilter(int L, double width) {
    std::vector<double> h(L + 1, 1.0);
    if (width <= 0.0) return h;
    for (int l = 0; l <= L; ++l) {
        double r = l / width;
        h[l] = std::exp(-0.5 * r * r);  // semi-Gaussian: h_0 = 1, falls off with the band
    }
    return h;
}

}  // namespace shrefract
