// Real spherical harmonics (paper eq. 6-7), to any order.
//
// Order L means bands l = 0..L, (L+1)^2 functions. Orthonormal on the sphere. Sign convention
// and index order: docs/conventions.md. Two independent evaluations are kept side by side:
//  - shPolynomial(): the symbolic Cartesian polynomial with exact integer coefficients (what the
//    GLSL generator emits);
//  - shEvalRecurrence(): associated Legendre recurrence in double precision (the reference).
// Only functions with l + m even survive the mirroring f(x, y, -z) = f(x, y, z); the bake stores
// just those, in "even order": l = 0..L, and within a band m = -l, -l+2, ..., l.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace shrefract {

// (L+1)^2: all real SH through order L.
inline int shCount(int L) { return (L + 1) * (L + 1); }
// (L+1)(L+2)/2: the even-parity (l + m even) functions through order L.
constexpr int shEvenCount(int L) { return (L + 1) * (L + 2) / 2; }
// Index of (l, m) among all functions: l^2 + l + m.
inline int shIndex(int l, int m) { return l * l + l + m; }
// Index of (l, m) among the even-parity functions (l + m even), in even order; -1 if l + m odd.
inline int shEvenIndex(int l, int m) {
    return ((l + m) & 1) ? -1 : l * (l + 1) / 2 + (m + l) / 2;
}

struct ShLM {
    int l = 0, m = 0;
};
// The even-parity functions through order L, in even order (size shEvenCount(L)).
std::vector<ShLM> shEvenFunctions(int L);

// Reference evaluation of y_l^m at the unit direction w, double precision, Legendre recurrence.
double shEvalRecurrence(int l, int m, glm::dvec3 w);
// All (L+1)^2 functions at w by the recurrence, indexed by shIndex.
void shEvalAllRecurrence(int L, glm::dvec3 w, double* out);
// The even-parity functions through order L at w (shEvenCount(L) values, even order), float.
// The fast path for the CPU decompressor and the tracer-side projection checks.
void shEvalEven(int L, glm::vec3 w, float* out);

// One term num * scale * x^a y^b z^c of an expanded polynomial.
struct Monomial {
    int a = 0, b = 0, c = 0;
    int64_t num = 0;  // exact integer numerator
};
// y_l^m as an exact polynomial: sum over terms of (num * scale) x^a y^b z^c, valid on the unit
// sphere. `scale` is the only rounded quantity (sqrt of a rational over pi, over a power of 2).
struct ShPolynomial {
    int l = 0, m = 0;
    double scale = 0.0;
    std::vector<Monomial> terms;
    // Sum of |num * scale|: the cancellation measure; digits lost ~ log10(absSum()).
    double absSum() const;
    double eval(glm::dvec3 w) const;
    std::string ToString() const;  // "y_3^-2 = ..." for failing tests and shader labels
};
ShPolynomial shPolynomial(int l, int m);

// The paper's semi-Gaussian low-pass on SH weights (§4.3): h_l = exp(-(l / width)^2 / 2) for
// l = 0..L; width <= 0 means no filter (all ones, the box filter of plain truncation).
std::vector<double> shBandFilter(int L, double width);

}  // namespace shrefract
