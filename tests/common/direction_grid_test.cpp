// Tests for common/direction_grid.h: the grid, its interpolation B_j, the compression matrix M
// (projection recovery, quadrature independence, agreement with a brute-force integral through
// interpolate()), the least-squares alternative and the on-disk cache.
#include "common/direction_grid.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/sh.h"
#include "support/random_direction.h"

namespace shrefract {
namespace {

constexpr double kPi = 3.14159265358979323846;

glm::dvec3 fromAngles(double theta, double phi) {
    return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

double interpolateValues(const DirectionGrid& g, const std::vector<double>& f, glm::dvec3 w) {
    int idx[4];
    double wt[4];
    int n = g.interpolate(w, idx, wt);
    double v = 0.0;
    for (int i = 0; i < n; ++i) v += wt[i] * f[idx[i]];
    return v;
}

std::vector<double> randomSamples(const DirectionGrid& g, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<double> f(g.count());
    for (double& v : f) v = u(rng);
    return f;
}

// Random coefficients of an even-parity function band-limited to order Lf; evaluated with the
// recurrence so that nothing here shares code with M.
struct BandLimited {
    int Lf;
    std::vector<double> coef;  // even order
    double operator()(glm::dvec3 w) const {
        std::vector<double> y(shCount(Lf));
        shEvalAllRecurrence(Lf, w, y.data());
        double v = 0.0;
        for (const ShLM& f : shEvenFunctions(Lf))
            v += coef[shEvenIndex(f.l, f.m)] * y[shIndex(f.l, f.m)];
        return v;
    }
};
BandLimited randomBandLimited(int Lf, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    BandLimited b{Lf, std::vector<double>(shEvenCount(Lf))};
    for (double& c : b.coef) c = u(rng);
    return b;
}

// max_e |(M R)_e - c_e| over the even functions through order L (c_e = 0 above Lf).
double recoveryError(const Eigen::MatrixXd& M, const DirectionGrid& g, const BandLimited& f,
                     int L) {
    Eigen::VectorXd R(g.count());
    for (int j = 0; j < g.count(); ++j) R(j) = f(g.direction(j));
    Eigen::VectorXd W = M * R;
    double err = 0.0;
    for (const ShLM& s : shEvenFunctions(L)) {
        double c = s.l <= f.Lf ? f.coef[shEvenIndex(s.l, s.m)] : 0.0;
        err = std::max(err, std::fabs(W(shEvenIndex(s.l, s.m)) - c));
    }
    return err;
}

TEST(DirectionGrid, Directions) {
    DirectionGrid g{4, 8};
    EXPECT_EQ(g.count(), 32);
    EXPECT_EQ(g.ToString(), "4x8");
    EXPECT_NEAR(g.theta(0), kPi / 16, 1e-15);
    EXPECT_NEAR(g.phi(7), 2 * kPi * 7.5 / 8, 1e-15);
    glm::dvec3 d = g.direction(2 * 8 + 3);
    glm::dvec3 e = fromAngles(g.theta(2), g.phi(3));
    EXPECT_NEAR(glm::length(d - e), 0.0, 1e-15);
    for (int j = 0; j < g.count(); ++j) EXPECT_GT(g.direction(j).z, 0.0);
}

TEST(DirectionGrid, ParseGrid) {
    DirectionGrid g = parseGrid("32x64");
    EXPECT_EQ(g.nTheta, 32);
    EXPECT_EQ(g.nPhi, 64);
    EXPECT_EQ(parseGrid("2x2").count(), 4);
    EXPECT_EQ(parseGrid("1024x1024").count(), 1024 * 1024);
    for (const char* bad : {"", "32", "32x", "x64", "32x63", "1x64", "32x1026", "32x0", "-4x8",
                            "32 x64", "32x64x2", "32X64", "3.5x64", "99999999999x4"}) {
        EXPECT_THROW(parseGrid(bad), InputError) << "'" << bad << "'";
    }
    try {
        parseGrid("32x63", "scene.json");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("scene.json: "), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("even"), std::string::npos) << e.what();
    }
}

TEST(DirectionGrid, InterpolationWeightsSumToOne) {
    DirectionGrid g{8, 16};
    std::mt19937_64 rng(1);
    for (int n = 0; n < 5000; ++n) {
        glm::dvec3 w = test::randomDirection(rng);
        int idx[4];
        double wt[4];
        int k = g.interpolate(w, idx, wt);
        ASSERT_GE(k, 1);
        ASSERT_LE(k, 4);
        double sum = 0.0;
        for (int i = 0; i < k; ++i) {
            EXPECT_GE(wt[i], 0.0);
            EXPECT_GE(idx[i], 0);
            EXPECT_LT(idx[i], g.count());
            sum += wt[i];
        }
        EXPECT_NEAR(sum, 1.0, 1e-14);
    }
}

// At a grid direction the neighbours get weights of rounding size only (the test allows 1e-13).
TEST(DirectionGrid, InterpolationReproducesSamples) {
    for (DirectionGrid g : {DirectionGrid{2, 2}, DirectionGrid{8, 16}, DirectionGrid{32, 64}}) {
        std::vector<double> f = randomSamples(g, 2);
        for (int j = 0; j < g.count(); ++j) {
            glm::dvec3 w = g.direction(j);
            EXPECT_NEAR(interpolateValues(g, f, w), f[j], 1e-13) << g.ToString() << " j=" << j;
            glm::dvec3 mirrored(w.x, w.y, -w.z);
            EXPECT_NEAR(interpolateValues(g, f, mirrored), f[j], 1e-13) << g.ToString();
        }
    }
}

// Across every seam the interpolant changes by O(eps) (bilinear, Lipschitz with constant
// ~ max|f| / cell size): phi wrap, the pole (phi to phi + pi), the cap boundary, the last ring,
// the equator. A wrong seam would jump by O(1) (random samples in [-1, 1]).
TEST(DirectionGrid, InterpolationContinuousAcrossSeams) {
    DirectionGrid g{8, 16};
    std::vector<double> f = randomSamples(g, 3);
    const double eps = 1e-9, tol = 1e-6;
    auto at = [&](double th, double ph) { return interpolateValues(g, f, fromAngles(th, ph)); };
    for (int n = 0; n < 64; ++n) {
        double th = (n + 0.3) / 64 * kPi;  // full sphere: exercises the mirror too
        EXPECT_NEAR(at(th, -eps), at(th, eps), tol) << "phi wrap at theta " << th;
        EXPECT_NEAR(at(th, 2 * kPi - eps), at(th, eps), tol);
    }
    for (int n = 0; n < 64; ++n) {
        double ph = (n + 0.7) / 64 * 2 * kPi;
        // Through the pole along a meridian.
        EXPECT_NEAR(at(eps, ph), at(eps, ph + kPi), tol) << "pole at phi " << ph;
        EXPECT_NEAR(at(kPi - eps, ph), at(kPi - eps, ph + kPi), tol) << "south pole";
        // Entering the cap and leaving the last ring.
        EXPECT_NEAR(at(g.theta(0) - eps, ph), at(g.theta(0) + eps, ph), tol);
        EXPECT_NEAR(at(g.theta(g.nTheta - 1) - eps, ph), at(g.theta(g.nTheta - 1) + eps, ph), tol);
        // The equator.
        EXPECT_NEAR(at(0.5 * kPi - eps, ph), at(0.5 * kPi + eps, ph), tol);
        // Constant past the last ring.
        EXPECT_NEAR(at(g.theta(g.nTheta - 1) + 0.01, ph), at(0.5 * kPi, ph), 1e-14);
    }
    // A sample-independent check that the cap really reflects: with f = 1 on column 0 of ring 0
    // only, the pole value is 1/2 along the meridian through column 0.
    std::vector<double> delta(g.count(), 0.0);
    delta[0] = 1.0;
    EXPECT_NEAR(interpolateValues(g, delta, fromAngles(1e-12, g.phi(0))), 0.5, 1e-9);
    EXPECT_NEAR(interpolateValues(g, delta, fromAngles(1e-12, g.phi(0) + kPi)), 0.5, 1e-9);
}


// M by brute force: q x q Gauss-Legendre points in every (theta, phi) cell of the upper
// hemisphere, B_j from interpolate(), y_i from the recurrence, doubled for the lower half.
// compressionMatrix() factors the same rule per axis, so they agree to rounding (measured 3e-16).
TEST(DirectionGrid, CompressionMatrixMatchesBruteForce) {
    const DirectionGrid g{4, 8};
    const int L = 6, q = 5;
    std::vector<double> gx, gw;
    gaussLegendre(q, &gx, &gw);
    std::vector<double> thetaEdges{0.0};
    for (int i = 0; i < g.nTheta; ++i) thetaEdges.push_back(g.theta(i));
    thetaEdges.push_back(0.5 * kPi);
    const double dPhi = 2 * kPi / g.nPhi;
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(shEvenCount(L), g.count());
    std::vector<double> y(shCount(L));
    for (size_t c = 0; c + 1 < thetaEdges.size(); ++c) {
        double ta = thetaEdges[c], tb = thetaEdges[c + 1];
        for (int k = 0; k < g.nPhi; ++k) {
            double pa = g.phi(k);
            for (int a = 0; a < q; ++a)
                for (int b = 0; b < q; ++b) {
                    double th = 0.5 * (ta + tb) + 0.5 * (tb - ta) * gx[a];
                    double ph = pa + 0.5 * dPhi * (1.0 + gx[b]);
                    double dw = 0.25 * (tb - ta) * dPhi * gw[a] * gw[b] * std::sin(th);
                    glm::dvec3 w = fromAngles(th, ph);
                    shEvalAllRecurrence(L, w, y.data());
                    int idx[4];
                    double wt[4];
                    int n = g.interpolate(w, idx, wt);
                    for (const ShLM& f : shEvenFunctions(L))
                        for (int i = 0; i < n; ++i)
                            B(shEvenIndex(f.l, f.m), idx[i]) +=
                                2.0 * y[shIndex(f.l, f.m)] * wt[i] * dw;
                }
        }
    }
    Eigen::MatrixXd M = compressionMatrix(g, L, q);
    ASSERT_EQ(M.rows(), shEvenCount(L));
    ASSERT_EQ(M.cols(), g.count());
    double diff = (M - B).cwiseAbs().maxCoeff();
    std::printf("  max |M - brute force| = %.3g (max |M| = %.3g)\n", diff, M.cwiseAbs().maxCoeff());
    EXPECT_LT(diff, 1e-14);
}

// W = M R recovers the coefficients of a band-limited even function up to the bilinear
// interpolation error, which is O(cell^2): it falls ~4x per grid refinement. Measured
// (random coefficients through order 4, M through order 8):
//   16x32: 2.8e-2,  32x64: 7.1e-3,  64x128: 1.8e-3 (coefficients in [-1, 1]); tolerances 1.4x,
// and each refinement must cut the error by at least ~3x (measured 3.96x, 3.99x).
TEST(DirectionGrid, ProjectionRecoversBandLimitedCoefficients) {
    const BandLimited f = randomBandLimited(4, 17);
    const int L = 8;
    const double tol[] = {4e-2, 1e-2, 2.5e-3};
    double prev = 0.0;
    int n = 0;
    for (DirectionGrid g : {DirectionGrid{16, 32}, DirectionGrid{32, 64}, DirectionGrid{64, 128}}) {
        double err = recoveryError(compressionMatrix(g, L), g, f, L);
        std::printf("  projection recovery %s: max coefficient error %.3g\n", g.ToString().c_str(),
                    err);
        EXPECT_LT(err, tol[n]) << g.ToString();
        if (n > 0) EXPECT_LT(err, 0.35 * prev) << "no O(h^2) convergence at " << g.ToString();
        prev = err;
        ++n;
    }
}

// The integrand is smooth within each cell, so Gauss-Legendre converges fast: q = 8 and
// q = 16 agree to rounding (measured 2.8e-15 relative), q = 4 vs q = 8 to 5.5e-10 relative
// (32x64, L = 8).
TEST(DirectionGrid, CompressionMatrixIndependentOfQuadrature) {
    const DirectionGrid g{32, 64};
    const int L = 8;
    Eigen::MatrixXd M4 = compressionMatrix(g, L, 4);
    Eigen::MatrixXd M8 = compressionMatrix(g, L, 8);
    Eigen::MatrixXd M16 = compressionMatrix(g, L, 16);
    double scale = M16.cwiseAbs().maxCoeff();
    double d48 = (M4 - M8).cwiseAbs().maxCoeff() / scale;
    double d816 = (M8 - M16).cwiseAbs().maxCoeff() / scale;
    std::printf("  relative max |M4 - M8| = %.3g, |M8 - M16| = %.3g\n", d48, d816);
    EXPECT_LT(d816, 1e-13);
    EXPECT_LT(d48, 1e-9);
    EXPECT_GT(d48, 0.0);  // q really changes the rule
}

// Timing on one core; the budget is "well under 1 s" at L = 8 and seconds at L = 16. Measured
// 0.2 ms (L = 8) and 0.7 ms (L = 16) at 32x64, q = 8: the cell rule factors per axis.
TEST(DirectionGrid, CompressionMatrixTiming) {
    const DirectionGrid g{32, 64};
    for (int L : {8, 16}) {
        auto t0 = std::chrono::steady_clock::now();
        Eigen::MatrixXd M = compressionMatrix(g, L, 8);
        double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::printf("  compressionMatrix L=%d 32x64 q=8: %.4f s\n", L, s);
        EXPECT_LT(s, L == 8 ? 0.5 : 2.0);
        EXPECT_EQ(M.rows(), shEvenCount(L));
    }
}

// The weighted least-squares fit reproduces any function in the span exactly (measured 3.3e-15),
// unlike projection, which carries the interpolation error.
TEST(DirectionGrid, LeastSquaresRecoversSpanExactly) {
    const DirectionGrid g{16, 32};
    const int L = 8;
    Eigen::MatrixXd P = leastSquaresMatrix(g, L);
    ASSERT_EQ(P.rows(), shEvenCount(L));
    ASSERT_EQ(P.cols(), g.count());
    double errFull = recoveryError(P, g, randomBandLimited(L, 5), L);
    double errLow = recoveryError(P, g, randomBandLimited(4, 17), L);
    std::printf("  least squares recovery: order 8 %.3g, order 4 %.3g\n", errFull, errLow);
    EXPECT_LT(errFull, 1e-12);
    EXPECT_LT(errLow, 1e-12);
}

// For a function outside the span the weights matter: weighted by each cell's solid angle, the
// fit minimizes a Riemann sum of the L2 error over the hemisphere, so as the grid refines it
// converges to the L2 projection (for even functions the hemisphere's is the sphere's). The
// reference: the projection of f = exp(0.8 x + 0.3 y) (1 + z^2), smooth and even in z, by
// Gauss-Legendre in z (48 nodes) times 96 uniform azimuths, exact to rounding for this entire
// function. Measured max coefficient error at order 4: 16x32 2.5e-6, 32x64 6.2e-7, 64x128
// 1.5e-7 (O(h^2)); thresholds 2x those, and at least 3x per refinement. Weighted per unit of
// theta instead (no sin theta), it stays at 2.6e-3 on every grid.
TEST(DirectionGrid, LeastSquaresConvergesToTheProjection) {
    const int L = 4;
    auto f = [](glm::dvec3 w) { return std::exp(0.8 * w.x + 0.3 * w.y) * (1 + w.z * w.z); };
    const std::vector<ShLM> fs = shEvenFunctions(L);
    std::vector<double> exact(fs.size(), 0.0), x, wz;
    gaussLegendre(48, &x, &wz);
    const int nPhi = 96;
    for (size_t i = 0; i < x.size(); ++i)
        for (int k = 0; k < nPhi; ++k) {
            const double phi = 2 * kPi * k / nPhi, s = std::sqrt(1 - x[i] * x[i]);
            const glm::dvec3 w(s * std::cos(phi), s * std::sin(phi), x[i]);
            for (size_t e = 0; e < fs.size(); ++e)
                exact[e] += wz[i] * (2 * kPi / nPhi) * f(w) * shEvalRecurrence(fs[e].l, fs[e].m, w);
        }
    const double tol[] = {5e-6, 1.3e-6, 3.2e-7};
    double prev = 0.0;
    int n = 0;
    for (DirectionGrid g : {DirectionGrid{16, 32}, DirectionGrid{32, 64}, DirectionGrid{64, 128}}) {
        Eigen::VectorXd r(g.count());
        for (int j = 0; j < g.count(); ++j) r(j) = f(g.direction(j));
        const Eigen::VectorXd c = leastSquaresMatrix(g, L) * r;
        double err = 0.0;
        for (size_t e = 0; e < fs.size(); ++e) err = std::max(err, std::abs(c(long(e)) - exact[e]));
        std::printf("  least squares vs projection %s: max coefficient error %.3g\n",
                    g.ToString().c_str(), err);
        EXPECT_LT(err, tol[n]) << g.ToString();
        if (n > 0) EXPECT_LT(err, prev / 3) << "no convergence at " << g.ToString();
        prev = err;
        ++n;
    }
}

TEST(DirectionGrid, CompressionMatrixCache) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::path(SHREFRACT_TEST_TMP) / "mcache";
    fs::remove_all(dir);
    const DirectionGrid g{8, 16};
    const int L = 4;
    Eigen::MatrixXd direct = compressionMatrix(g, L, 8);
    Eigen::MatrixXd first = compressionMatrixCached(g, L, dir.string());
    EXPECT_EQ((first - direct).cwiseAbs().maxCoeff(), 0.0);
    const fs::path file = dir / "shM_L4_8x16_q8.bin";
    ASSERT_TRUE(fs::exists(file));
    for (const auto& e : fs::directory_iterator(dir))  // no temporary left behind
        EXPECT_EQ(e.path().filename(), file.filename());

    auto bytes = [&] {
        std::ifstream in(file, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    const std::string original = bytes();

    // Read back: bit-identical, and the file is not rewritten (its old timestamp stays).
    const auto old = fs::file_time_type::clock::now() - std::chrono::hours(24);
    fs::last_write_time(file, old);
    Eigen::MatrixXd again = compressionMatrixCached(g, L, dir.string());
    EXPECT_EQ((again - direct).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(fs::last_write_time(file), old) << "cache file was rewritten instead of read";

    // Flip one data byte, same size: the checksum catches it, the matrix is recomputed and the
    // file rewritten with the original content.
    const auto size = fs::file_size(file);
    {
        std::fstream io(file, std::ios::in | std::ios::out | std::ios::binary);
        io.seekp(std::streamoff(size - 3));
        io.put('\x7f');
    }
    ASSERT_NE(bytes(), original);
    Eigen::MatrixXd repaired = compressionMatrixCached(g, L, dir.string());
    EXPECT_EQ((repaired - direct).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(bytes(), original);
    // Truncated file and garbage: recomputed too.
    fs::resize_file(file, 20);
    EXPECT_EQ((compressionMatrixCached(g, L, dir.string()) - direct).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(bytes(), original);
    { std::ofstream(file, std::ios::binary) << "not a matrix"; }
    EXPECT_EQ((compressionMatrixCached(g, L, dir.string()) - direct).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(bytes(), original);
    // Another q is another file.
    compressionMatrixCached(g, L, dir.string(), 4);
    EXPECT_TRUE(fs::exists(dir / "shM_L4_8x16_q4.bin"));
    // Empty cacheDir: no file at all.
    EXPECT_EQ((compressionMatrixCached(g, L, "") - direct).cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace
}  // namespace shrefract

namespace shrefract {
namespace {

// The quadrature the compression matrix and the SH tests rely on: q nodes integrate x^k over
// [-1, 1] exactly (2/(k+1) for even k, 0 for odd) up to k = 2q - 1, and not beyond.
TEST(Quadrature, GaussLegendreIsExactToDegreeTwoQMinusOne) {
    for (int q : {1, 2, 4, 8, 16}) {
        std::vector<double> x, w;
        gaussLegendre(q, &x, &w);
        for (int k = 0; k <= 2 * q; ++k) {
            double sum = 0;
            for (int i = 0; i < q; ++i) sum += w[i] * std::pow(x[i], k);
            const double exact = (k % 2) ? 0.0 : 2.0 / (k + 1);
            if (k <= 2 * q - 1)
                EXPECT_NEAR(sum, exact, 1e-13) << "q " << q << " k " << k;
            else
                // Degree 2q is not exact; its error shrinks with q (measured 7.2e-10 at q = 16).
                EXPECT_GT(std::abs(sum - exact), 1e-11) << "q " << q << " degree 2q is not exact";
        }
    }
}

}  // namespace
}  // namespace shrefract
