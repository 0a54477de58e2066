// STAND-IN, compiled only while common/sh.cpp does not exist (branch h-sh not merged yet): just
// enough of common/sh.h for the runtime to link and be tested. Same math as the paper's eq. 6-7
// written as y_l^m = K * Re/Im((x + iy)^|m|) * d^|m|/dz^|m| P_l(z), without the Condon-Shortley
// phase. Delete this file when h-sh lands (runtime/CMakeLists.txt stops compiling it anyway).
#include <cmath>
#include <cstdio>
#include <mutex>
#include <sstream>

#include "common/sh.h"

namespace shrefract {

namespace {

int64_t binomial(int n, int k) {
    if (k < 0 || k > n) return 0;
    int64_t r = 1;
    for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
    return r;
}

double factorial(int n) {
    double r = 1;
    for (int i = 2; i <= n; ++i) r *= i;
    return r;
}

}  // namespace

std::vector<ShLM> shEvenFunctions(int L) {
    std::vector<ShLM> out;
    for (int l = 0; l <= L; ++l)
        for (int m = -l; m <= l; m += 2) out.push_back({l, m});
    return out;
}

ShPolynomial shPolynomial(int l, int m) {
    const int am = std::abs(m);
    ShPolynomial p;
    p.l = l;
    p.m = m;
    // K_l^|m| (sqrt 2 for m != 0) over the 2^l of Rodrigues' formula.
    p.scale = std::sqrt((2 * l + 1) / (4 * M_PI) * factorial(l - am) / factorial(l + am)) *
              (m != 0 ? std::sqrt(2.0) : 1.0) / std::ldexp(1.0, l);
    for (int k = 0; 2 * k <= l; ++k) {
        int zp = l - 2 * k;  // P_l term z^zp, coefficient (-1)^k C(l,k) C(2l-2k,l)
        if (zp < am) continue;
        int64_t legendre = ((k & 1) ? -1 : 1) * binomial(l, k) * binomial(2 * l - 2 * k, l);
        int64_t falling = 1;  // d^|m|/dz^|m| z^zp
        for (int i = 0; i < am; ++i) falling *= (zp - i);
        for (int j = 0; j <= am; ++j) {
            bool odd = j & 1;
            if ((m >= 0) == odd) continue;  // Re takes even powers of iy, Im the odd ones
            int64_t sign = (((odd ? j - 1 : j) / 2) & 1) ? -1 : 1;
            Monomial t;
            t.a = am - j;
            t.b = j;
            t.c = zp - am;
            t.num = legendre * falling * sign * binomial(am, j);
            if (t.num != 0) p.terms.push_back(t);
        }
    }
    return p;
}

double ShPolynomial::absSum() const {
    double s = 0;
    for (const Monomial& t : terms) s += std::abs(static_cast<double>(t.num) * scale);
    return s;
}

double ShPolynomial::eval(glm::dvec3 w) const {
    double s = 0;
    for (const Monomial& t : terms)
        s += static_cast<double>(t.num) * std::pow(w.x, t.a) * std::pow(w.y, t.b) *
             std::pow(w.z, t.c);
    return s * scale;
}

std::string ShPolynomial::ToString() const {
    std::ostringstream os;
    os << "y_" << l << "^" << m << " = " << scale << " * (";
    for (size_t i = 0; i < terms.size(); ++i) {
        const Monomial& t = terms[i];
        os << (i ? (t.num < 0 ? " - " : " + ") : (t.num < 0 ? "-" : "")) << std::llabs(t.num);
        for (auto [v, e] : {std::pair{'x', t.a}, {'y', t.b}, {'z', t.c}})
            for (int k = 0; k < e; ++k) os << ' ' << v;
    }
    os << ")";
    return os.str();
}

void shEvalEven(int L, glm::vec3 w, float* out) {
    static std::mutex mutex;
    static std::vector<ShPolynomial> cache;
    std::lock_guard<std::mutex> lock(mutex);
    std::vector<ShLM> fs = shEvenFunctions(L);
    while (cache.size() < fs.size()) {
        ShLM f = fs[cache.size()];
        cache.push_back(shPolynomial(f.l, f.m));
    }
    for (size_t k = 0; k < fs.size(); ++k) out[k] = static_cast<float>(cache[k].eval(w));
}

}  // namespace shrefract
