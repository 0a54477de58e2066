// Tests for common/sh.h: the exact polynomials against the Legendre recurrence, orthonormality,
// the sign convention, even-parity storage and the band filter.
#include "common/direction_grid.h"
#include "common/sh.h"
#include "support/random_direction.h"

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace shrefract {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Sphere quadrature: Gauss-Legendre in z (nz nodes, exact to degree 2 nz - 1) times the
// trapezoid rule in phi (nPhi points, exact for trigonometric degree < nPhi). Calls f(w, weight).
template <class F>
void sphereQuadrature(int nz, int nPhi, F&& f) {
    std::vector<double> zs, ws;
    gaussLegendre(nz, &zs, &ws);
    for (int a = 0; a < nz; ++a) {
        double s = std::sqrt(1.0 - zs[a] * zs[a]);
        for (int k = 0; k < nPhi; ++k) {
            double ph = 2.0 * kPi * (k + 0.25) / nPhi;
            f(glm::dvec3(s * std::cos(ph), s * std::sin(ph), zs[a]), ws[a] * 2.0 * kPi / nPhi);
        }
    }
}

TEST(SH, IndexOrders) {
    const int L = 6;
    std::vector<ShLM> fs = shEvenFunctions(L);
    ASSERT_EQ(int(fs.size()), shEvenCount(L));
    for (int e = 0; e < int(fs.size()); ++e) {
        EXPECT_EQ(shEvenIndex(fs[e].l, fs[e].m), e);
        EXPECT_EQ((fs[e].l + fs[e].m) % 2, 0);
    }
    EXPECT_EQ(shEvenIndex(3, 0), -1);
    EXPECT_EQ(shIndex(2, -2), 4);
    EXPECT_EQ(shCount(8), 81);
    EXPECT_EQ(shEvenCount(8), 45);
}

// Gram matrix of all (L+1)^2 functions by a quadrature exact for the degree-2L products.
// Measured max |G - I|: recurrence L = 8: 3.9e-15, L = 16: 7.0e-15; polynomials L = 8: 5.4e-15.
TEST(SH, OrthonormalByQuadrature) {
    auto check = [](int L, bool poly, double tol) {
        const int n = shCount(L);
        std::vector<ShPolynomial> polys;
        if (poly)
            for (int l = 0; l <= L; ++l)
                for (int m = -l; m <= l; ++m) polys.push_back(shPolynomial(l, m));
        std::vector<double> G(n * n, 0.0), y(n);
        sphereQuadrature(L + 2, 2 * L + 3, [&](glm::dvec3 w, double dw) {
            if (poly) {
                for (int i = 0; i < n; ++i) y[i] = polys[i].eval(w);
            } else {
                shEvalAllRecurrence(L, w, y.data());
            }
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) G[i * n + j] += y[i] * y[j] * dw;
        });
        double worst = 0.0;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j)
                worst = std::max(worst, std::fabs(G[i * n + j] - (i == j ? 1.0 : 0.0)));
        std::printf("  orthonormality L=%d %s: max |G - I| = %.3g\n", L,
                    poly ? "polynomial" : "recurrence", worst);
        EXPECT_LT(worst, tol) << "L=" << L << (poly ? " polynomial" : " recurrence");
    };
    check(8, false, 1e-12);
    check(16, false, 1e-12);
    check(8, true, 1e-12);
}

// The exact polynomial and the double recurrence are independent; their difference is the
// rounding of the polynomial's cancelling sum, bounded by ~absSum() * DBL_EPSILON.
// Measured (2004 directions per function, worst over m):
//   l = 8:  max error 1.8e-14, max absSum 3.5e2
//   l = 16: max error 1.8e-11, max absSum 7.7e5
//   l = 20: max error 5.0e-10, max absSum 3.6e7
// Worst error / (absSum * DBL_EPSILON) over all l <= 20: 2.4. Tolerance: 8 absSum eps + 1e-15.
TEST(SH, PolynomialMatchesRecurrence) {
    std::mt19937_64 rng(7);
    std::vector<glm::dvec3> dirs(2000);
    for (auto& d : dirs) d = test::randomDirection(rng);
    // Include the poles and the equator.
    dirs.push_back({0, 0, 1});
    dirs.push_back({0, 0, -1});
    dirs.push_back({1, 0, 0});
    dirs.push_back(glm::normalize(glm::dvec3(1, -1, 0)));
    double worstRatio = 0.0;
    for (int l = 0; l <= 20; ++l) {
        double maxErr = 0.0, maxAbs = 0.0;
        for (int m = -l; m <= l; ++m) {
            ShPolynomial p = shPolynomial(l, m);
            double tol = 8.0 * p.absSum() * DBL_EPSILON + 1e-15;
            maxAbs = std::max(maxAbs, p.absSum());
            for (const glm::dvec3& w : dirs) {
                double err = std::fabs(p.eval(w) - shEvalRecurrence(l, m, w));
                maxErr = std::max(maxErr, err);
                worstRatio = std::max(worstRatio, err / (p.absSum() * DBL_EPSILON));
                ASSERT_LE(err, tol)
                    << p.ToString() << " at (" << w.x << ", " << w.y << ", " << w.z << ")";
            }
        }
        if (l == 4 || l == 8 || l == 12 || l == 16 || l == 20)
            std::printf("  l=%2d: max |poly - recurrence| = %.3g, max absSum = %.3g\n", l, maxErr,
                        maxAbs);
    }
    std::printf("  worst error / (absSum eps) = %.3g\n", worstRatio);
}

// No Condon-Shortley phase: y_1^1 ~ +x, y_1^-1 ~ +y, y_1^0 ~ +z; closed forms of low orders.
TEST(SH, SignConventionAgainstClosedForms) {
    std::mt19937_64 rng(3);
    for (int n = 0; n < 50; ++n) {
        glm::dvec3 w = test::randomDirection(rng);
        double x = w.x, y = w.y, z = w.z;
        const double c1 = std::sqrt(3.0 / (4.0 * kPi));
        struct Case {
            int l, m;
            double expect;
        } cases[] = {
            {0, 0, 0.5 / std::sqrt(kPi)},
            {1, -1, c1 * y},
            {1, 0, c1 * z},
            {1, 1, c1 * x},
            {2, -2, 0.5 * std::sqrt(15.0 / kPi) * x * y},
            {2, -1, 0.5 * std::sqrt(15.0 / kPi) * y * z},
            {2, 0, 0.25 * std::sqrt(5.0 / kPi) * (3 * z * z - 1)},
            {2, 1, 0.5 * std::sqrt(15.0 / kPi) * x * z},
            {2, 2, 0.25 * std::sqrt(15.0 / kPi) * (x * x - y * y)},
            {3, -3, 0.25 * std::sqrt(35.0 / (2 * kPi)) * (3 * x * x - y * y) * y},
            {3, 3, 0.25 * std::sqrt(35.0 / (2 * kPi)) * (x * x - 3 * y * y) * x},
            {3, 0, 0.25 * std::sqrt(7.0 / kPi) * (5 * z * z * z - 3 * z)},
        };
        for (const Case& c : cases) {
            ShPolynomial p = shPolynomial(c.l, c.m);
            EXPECT_NEAR(shEvalRecurrence(c.l, c.m, w), c.expect, 1e-14) << p.ToString();
            EXPECT_NEAR(p.eval(w), c.expect, 1e-14) << p.ToString();
        }
    }
    // Exact integers: y_2^0 = (1/4) sqrt(5/pi) (3 z^2 - 1), y_2^-2 = (1/2) sqrt(15/pi) x y.
    ShPolynomial p20 = shPolynomial(2, 0);
    ASSERT_EQ(p20.terms.size(), 2u) << p20.ToString();
    EXPECT_EQ(p20.terms[0].c, 2);
    EXPECT_EQ(p20.terms[0].num, 3);
    EXPECT_EQ(p20.terms[1].c, 0);
    EXPECT_EQ(p20.terms[1].num, -1);
    EXPECT_DOUBLE_EQ(p20.scale, 0.25 * std::sqrt(5.0 / kPi));
    EXPECT_EQ(p20.ToString(), "y_2^0 = 0.31539156525251999 * (3 z^2 - 1)");
    ShPolynomial p22 = shPolynomial(2, -2);
    ASSERT_EQ(p22.terms.size(), 1u) << p22.ToString();
    EXPECT_EQ(p22.terms[0].num, 1);
    EXPECT_EQ(p22.terms[0].a, 1);
    EXPECT_EQ(p22.terms[0].b, 1);
    EXPECT_DOUBLE_EQ(p22.scale, 0.5 * std::sqrt(15.0 / kPi));
}

// Parity: y_l^m(x, y, -z) = (-1)^(l+m) y_l^m(x, y, z), so a z-symmetric function has zero
// odd-parity coefficients. Projection by full-sphere quadrature (nodes symmetric in z), not M.
// Measured: max |odd| = 2.4e-15, max |even| = 9.0 (33 of 45 even ones above 1e-3).
TEST(SH, MirroredFunctionHasNoOddParityCoefficients) {
    const int L = 8;
    // Symmetric in z but not smooth there: f(x, y, -z) = f(x, y, z).
    auto f = [](glm::dvec3 w) {
        return std::exp(w.x - 0.5 * w.y) * (1.0 + std::fabs(w.z)) + std::cos(3.0 * w.z * w.x);
    };
    std::vector<double> coef(shCount(L), 0.0), y(shCount(L));
    sphereQuadrature(64, 129, [&](glm::dvec3 w, double dw) {
        shEvalAllRecurrence(L, w, y.data());
        double v = f(w);
        for (int i = 0; i < shCount(L); ++i) coef[i] += v * y[i] * dw;
    });
    double maxOdd = 0.0, maxEven = 0.0;
    int evenNonzero = 0;
    for (int l = 0; l <= L; ++l)
        for (int m = -l; m <= l; ++m) {
            double c = std::fabs(coef[shIndex(l, m)]);
            if ((l + m) & 1) {
                maxOdd = std::max(maxOdd, c);
                EXPECT_LT(c, 1e-12) << "y_" << l << "^" << m;
            } else {
                maxEven = std::max(maxEven, c);
                evenNonzero += c > 1e-3;
            }
        }
    std::printf("  max |odd| = %.3g, max |even| = %.3g, even > 1e-3: %d\n", maxOdd, maxEven,
                evenNonzero);
    EXPECT_GT(evenNonzero, 10);
}

// The float fast path against the double reference. Measured max error (L = 16): 3.7e-6;
// tolerance 2e-5.
TEST(SH, EvalEvenMatchesRecurrence) {
    const int L = 16;
    std::mt19937_64 rng(11);
    std::vector<float> out(shEvenCount(L));
    std::vector<double> ref(shCount(L));
    double worst = 0.0;
    for (int n = 0; n < 500; ++n) {
        glm::dvec3 w = n == 0 ? glm::dvec3(0, 0, 1) : test::randomDirection(rng);
        shEvalEven(L, glm::vec3(w), out.data());
        shEvalAllRecurrence(L, glm::dvec3(glm::vec3(w)), ref.data());
        for (const ShLM& f : shEvenFunctions(L)) {
            double err = std::fabs(out[shEvenIndex(f.l, f.m)] - ref[shIndex(f.l, f.m)]);
            worst = std::max(worst, err);
            ASSERT_LT(err, 2e-5) << "y_" << f.l << "^" << f.m;
        }
    }
    std::printf("  shEvalEven L=16: max |float - double| = %.3g\n", worst);
}

TEST(SH, EvalAllMatchesSingle) {
    const int L = 10;
    std::mt19937_64 rng(5);
    std::vector<double> all(shCount(L));
    for (int n = 0; n < 20; ++n) {
        glm::dvec3 w = test::randomDirection(rng);
        shEvalAllRecurrence(L, w, all.data());
        for (int l = 0; l <= L; ++l)
            for (int m = -l; m <= l; ++m)
                EXPECT_NEAR(all[shIndex(l, m)], shEvalRecurrence(l, m, w), 1e-13);
    }
}

TEST(SH, ConstantProjectsToBandZeroOnly) {
    const int L = 6;
    std::vector<double> coef(shCount(L), 0.0), y(shCount(L));
    sphereQuadrature(L + 2, 2 * L + 3, [&](glm::dvec3 w, double dw) {
        shEvalAllRecurrence(L, w, y.data());
        for (int i = 0; i < shCount(L); ++i) coef[i] += 1.0 * y[i] * dw;
    });
    EXPECT_NEAR(coef[0], 2.0 * std::sqrt(kPi), 1e-13);  // ∫ y_0^0 = 4 pi / sqrt(4 pi)
    for (int i = 1; i < shCount(L); ++i) EXPECT_NEAR(coef[i], 0.0, 1e-13) << "index " << i;
}

TEST(SH, BandFilter) {
    std::vector<double> box = shBandFilter(8, 0.0);
    ASSERT_EQ(box.size(), 9u);
    for (double h : box) EXPECT_EQ(h, 1.0);
    std::vector<double> h = shBandFilter(8, 4.0);
    EXPECT_EQ(h[0], 1.0);
    EXPECT_NEAR(h[4], std::exp(-0.5), 1e-15);
    EXPECT_NEAR(h[8], std::exp(-2.0), 1e-15);
    for (int l = 1; l <= 8; ++l) EXPECT_LT(h[l], h[l - 1]);
}

}  // namespace
}  // namespace shrefract
