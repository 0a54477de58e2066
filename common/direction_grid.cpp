// The direction grid over the outer hemisphere, its interpolation B_j, and the compression
// matrix M_ij = ∫_{S^2} y_i B_j ds (paper eq. 8-10). Conventions: docs/conventions.md.
#include "common/direction_grid.h"

#include <unistd.h>

#include <Eigen/Dense>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "common/error.h"
#include "common/limits.h"
#include "common/output.h"
#include "common/sh.h"

namespace shrefract {

namespace {

constexpr double kPi = 3.14159265358979323846;

void checkGrid(const DirectionGrid& g) {
    SHREFRACT_CHECK(g.nTheta >= 1 && g.nPhi >= 2 && g.nPhi % 2 == 0);
}

// Normalized associated Legendre Pbar_l^m(cos theta) = K_l^m P_l^m (no Condon-Shortley phase),
// all 0 <= m <= l <= L, stored at l*(l+1)/2 + m.
void legendreAll(int L, double theta, double* out) {
    double z = std::cos(theta), s = std::sin(theta);
    double pmm = 1.0 / std::sqrt(4.0 * kPi);
    for (int m = 0; m <= L; ++m) {
        if (m > 0) pmm *= std::sqrt((2.0 * m + 1.0) / (2.0 * m)) * s;
        double p2 = pmm, p1 = 0.0;
        out[m * (m + 1) / 2 + m] = pmm;
        if (m == L) continue;
        p1 = std::sqrt(2.0 * m + 3.0) * z * pmm;
        out[(m + 1) * (m + 2) / 2 + m] = p1;
        for (int l = m + 2; l <= L; ++l) {
            double a = std::sqrt((4.0 * l * l - 1.0) / (double(l) * l - double(m) * m));
            double b = std::sqrt((double(l - 1) * (l - 1) - double(m) * m) /
                                 (4.0 * (l - 1) * (l - 1) - 1.0));
            double p = a * (z * p1 - b * p2);
            out[l * (l + 1) / 2 + m] = p;
            p2 = p1;
            p1 = p;
        }
    }
}

// Solid angle of sample j's cell (theta in [i, i+1] dTheta, phi in [k, k+1] dPhi).
double cellSolidAngle(const DirectionGrid& g, int i) {
    double dTheta = 0.5 * kPi / g.nTheta, dPhi = 2.0 * kPi / g.nPhi;
    return dPhi * (std::cos(i * dTheta) - std::cos((i + 1) * dTheta));
}

// --- cache file -------------------------------------------------------------------------------

constexpr char kCacheMagic[8] = {'S', 'H', 'R', 'F', 'M', 'A', 'T', '1'};
struct CacheHeader {
    char magic[8];
    int32_t L, nTheta, nPhi, q;
    int64_t rows, cols;
    uint64_t checksum;  // FNV-1a 64 over the matrix bytes
};

uint64_t fnv1a(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

std::string cachePath(const DirectionGrid& g, int L, int q, const std::string& dir) {
    std::ostringstream os;
    os << "shM_L" << L << "_" << g.ToString() << "_q" << q << ".bin";
    return (std::filesystem::path(dir) / os.str()).string();
}

bool readCache(const std::string& path, const DirectionGrid& g, int L, int q, Eigen::MatrixXd* M) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    CacheHeader h;
    if (!in.read(reinterpret_cast<char*>(&h), sizeof h)) return false;
    if (std::memcmp(h.magic, kCacheMagic, 8) != 0 || h.L != L || h.nTheta != g.nTheta ||
        h.nPhi != g.nPhi || h.q != q || h.rows != shEvenCount(L) || h.cols != g.count())
        return false;
    Eigen::MatrixXd m(h.rows, h.cols);
    const std::streamsize bytes = std::streamsize(m.size() * sizeof(double));
    if (!in.read(reinterpret_cast<char*>(m.data()), bytes)) return false;
    if (in.peek() != std::char_traits<char>::eof()) return false;  // trailing bytes
    if (fnv1a(m.data(), size_t(bytes)) != h.checksum) return false;
    *M = std::move(m);
    return true;
}

// Writes through writeAtomically (common/output.h): readers never see a half-written file, a
// killed bake leaves no temporary, and concurrent writers of the same matrix just race to
// identical content. A cache that cannot be written is no error: returns false.
bool writeCache(const std::string& path, const DirectionGrid& g, int L, int q,
                const Eigen::MatrixXd& M) {
    CacheHeader h;
    std::memcpy(h.magic, kCacheMagic, 8);
    h.L = L;
    h.nTheta = g.nTheta;
    h.nPhi = g.nPhi;
    h.q = q;
    h.rows = M.rows();
    h.cols = M.cols();
    h.checksum = fnv1a(M.data(), size_t(M.size()) * sizeof(double));
    std::string bytes(reinterpret_cast<const char*>(&h), sizeof h);
    bytes.append(reinterpret_cast<const char*>(M.data()), size_t(M.size()) * sizeof(double));
    try {
        writeFile(path, bytes);
        return true;
    } catch (const std::exception&) {
        return false;
    }
}

}  // namespace

// Newton on P_q from Chebyshev guesses.
void gaussLegendre(int q, std::vector<double>* x, std::vector<double>* w) {
    x->assign(q, 0.0);
    w->assign(q, 0.0);
    for (int i = 0; i < q; ++i) {
        double t = std::cos(kPi * (i + 0.75) / (q + 0.5));
        double dp = 1.0;
        for (int it = 0; it < 100; ++it) {
            double p0 = 1.0, p1 = t;  // P_0, P_1; Bonnet: n P_n = (2n-1) t P_{n-1} - (n-1) P_{n-2}
            for (int n = 2; n <= q; ++n) {
                double p2 = ((2.0 * n - 1.0) * t * p1 - (n - 1.0) * p0) / n;
                p0 = p1;
                p1 = p2;
            }
            dp = q * (t * p1 - p0) / (t * t - 1.0);  // P_q'(t)
            double dt = p1 / dp;
            t -= dt;
            if (std::fabs(dt) < 1e-16) break;
        }
        (*x)[i] = t;
        (*w)[i] = 2.0 / ((1.0 - t * t) * dp * dp);
    }
}


double DirectionGrid::theta(int i) const { return (i + 0.5) * (0.5 * kPi) / nTheta; }
double DirectionGrid::phi(int k) const { return (k + 0.5) * (2.0 * kPi) / nPhi; }

glm::dvec3 DirectionGrid::direction(int j) const {
    double t = theta(j / nPhi), p = phi(j % nPhi);
    return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

int DirectionGrid::interpolate(glm::dvec3 w, int index[4], double weight[4]) const {
    checkGrid(*this);
    SHREFRACT_CHECK(std::isfinite(w.x) && std::isfinite(w.y) && std::isfinite(w.z));
    const double dTheta = 0.5 * kPi / nTheta, dPhi = 2.0 * kPi / nPhi;
    // Mirror to z >= 0: f(x, y, -z) = f(x, y, z).
    double th = std::atan2(std::hypot(w.x, w.y), std::fabs(w.z));  // [0, pi/2]
    double ph = std::atan2(w.y, w.x);
    if (ph < 0.0) ph += 2.0 * kPi;

    // phi: samples at (k + 1/2) dPhi; v is the continuous column, wrapping at 2 pi.
    double v = ph / dPhi - 0.5;
    double kf = std::floor(v);
    double s = v - kf;  // weight of column k1
    int k0 = ((int(kf) % nPhi) + nPhi) % nPhi;
    int k1 = (k0 + 1) % nPhi;

    double u = th / dTheta - 0.5;  // continuous ring index
    if (u >= nTheta - 1) {
        // Past the last ring: constant in theta (bilinear between the ring and its mirror image).
        int r = nTheta - 1;
        index[0] = r * nPhi + k0, weight[0] = 1.0 - s;
        index[1] = r * nPhi + k1, weight[1] = s;
        return 2;
    }
    if (u < 0.0) {
        // Pole cap: the meridian through the pole continues at phi + pi, where ring 0 sits at
        // theta = -theta_0. Linear between -theta_0 (opposite samples) and theta_0 (these).
        const int h = nPhi / 2;
        double t = u + 1.0;  // (theta + theta_0) / (2 theta_0), theta_0 = dTheta / 2
        index[0] = k0, weight[0] = t * (1.0 - s);
        index[1] = k1, weight[1] = t * s;
        index[2] = (k0 + h) % nPhi, weight[2] = (1.0 - t) * (1.0 - s);
        index[3] = (k1 + h) % nPhi, weight[3] = (1.0 - t) * s;
        return 4;
    }
    int i0 = std::min(int(u), nTheta - 2);
    double t = u - i0;  // weight of ring i0 + 1
    index[0] = i0 * nPhi + k0, weight[0] = (1.0 - t) * (1.0 - s);
    index[1] = i0 * nPhi + k1, weight[1] = (1.0 - t) * s;
    index[2] = (i0 + 1) * nPhi + k0, weight[2] = t * (1.0 - s);
    index[3] = (i0 + 1) * nPhi + k1, weight[3] = t * s;
    return 4;
}

std::string DirectionGrid::ToString() const {
    return std::to_string(nTheta) + "x" + std::to_string(nPhi);
}

DirectionGrid parseGrid(const std::string& text, const std::string& what) {
    auto bad = [&](const std::string& why) {
        return inputError(what, "bad direction grid '" + text + "': " + why);
    };
    size_t x = text.find('x');
    auto digits = [](const std::string& s) {
        if (s.empty() || s.size() > 6) return false;
        for (char c : s)
            if (!std::isdigit(static_cast<unsigned char>(c))) return false;
        return true;
    };
    if (x == std::string::npos || !digits(text.substr(0, x)) || !digits(text.substr(x + 1)))
        throw bad("expected NTHETAxNPHI, e.g. 32x64");
    DirectionGrid g;
    g.nTheta = std::stoi(text.substr(0, x));
    g.nPhi = std::stoi(text.substr(x + 1));
    const std::string problem = gridProblem(g.nTheta, g.nPhi);
    if (!problem.empty()) throw bad(problem);
    return g;
}

std::string gridProblem(int nTheta, int nPhi) {
    if (nTheta < limits::kMinGrid || nTheta > limits::kMaxGrid || nPhi < limits::kMinGrid ||
        nPhi > limits::kMaxGrid)
        return "counts must lie in [" + std::to_string(limits::kMinGrid) + ", " +
               std::to_string(limits::kMaxGrid) + "]";
    if (nPhi % 2 != 0) return "NPHI must be even (the pole reflection maps phi to phi + pi)";
    return "";
}

Eigen::MatrixXd compressionMatrix(const DirectionGrid& grid, int L, int q) {
    checkGrid(grid);
    SHREFRACT_CHECK(L >= 0 && q >= 1);
    const int nT = grid.nTheta, nP = grid.nPhi;
    const double dTheta = 0.5 * kPi / nT, dPhi = 2.0 * kPi / nP;
    std::vector<double> gx, gw;
    gaussLegendre(q, &gx, &gw);

    // B_j is a tensor product within every cell: a hat in theta times a hat in phi (the pole cap
    // adds the phi + pi reflection, the band past the last ring is constant in theta), and
    // y_l^m = Pbar_l^|m|(cos theta) T_m(phi). So the q x q Gauss-Legendre rule over each cell
    // factors exactly into 1D rules:
    //   M_(l,m),(i,k) = 2 Theta_l^|m|(i) Phi_m(k),   (2: the mirrored lower hemisphere)
    //   Theta_l^m(i) = ∫_0^{pi/2} Pbar_l^m(cos theta) hat_i(theta) sin theta dtheta,
    //   Phi_m(k)     = ∫_0^{2 pi} T_m(phi) hat_k(phi) dphi.
    const int nLeg = (L + 1) * (L + 2) / 2;
    auto leg = [&](int l, int m) { return l * (l + 1) / 2 + m; };
    Eigen::MatrixXd Theta = Eigen::MatrixXd::Zero(nLeg, nT);
    std::vector<double> p(nLeg);
    // One theta cell [ta, tb]: f(theta) gives, per node, (ring, weight) contributions.
    auto thetaCell = [&](double ta, double tb, auto&& accumulate) {
        for (int g = 0; g < q; ++g) {
            double th = 0.5 * (ta + tb) + 0.5 * (tb - ta) * gx[g];
            double dw = 0.5 * (tb - ta) * gw[g] * std::sin(th);  // ds = sin theta dtheta dphi
            legendreAll(L, th, p.data());
            accumulate(th, dw);
        }
    };
    // Pole cap [0, theta_0]: weight t = (theta + theta_0) / (2 theta_0) at phi, 1 - t at phi + pi;
    // the phi + pi half turns T_m(phi) into (-1)^m T_m(phi).
    const double th0 = grid.theta(0);
    thetaCell(0.0, th0, [&](double th, double dw) {
        double t = (th + th0) / (2.0 * th0);
        for (int l = 0; l <= L; ++l)
            for (int m = 0; m <= l; ++m)
                Theta(leg(l, m), 0) += p[leg(l, m)] * dw * (t + ((m & 1) ? -1.0 : 1.0) * (1.0 - t));
    });
    // Between rings i and i + 1: linear in theta.
    for (int i = 0; i + 1 < nT; ++i) {
        double ta = grid.theta(i), tb = grid.theta(i + 1);
        thetaCell(ta, tb, [&](double th, double dw) {
            double t = (th - ta) / dTheta;
            for (int e = 0; e < nLeg; ++e) {
                Theta(e, i) += p[e] * dw * (1.0 - t);
                Theta(e, i + 1) += p[e] * dw * t;
            }
        });
    }
    // Past the last ring to the equator: constant.
    thetaCell(grid.theta(nT - 1), 0.5 * kPi, [&](double, double dw) {
        for (int e = 0; e < nLeg; ++e) Theta(e, nT - 1) += p[e] * dw;
    });

    // Phi_m(k): cells [phi_k, phi_k + dPhi], hat weights to columns k and k + 1 (wrapping).
    Eigen::MatrixXd Phi = Eigen::MatrixXd::Zero(2 * L + 1, nP);  // row m + L
    std::vector<double> cosm(L + 1), sinm(L + 1);
    for (int k = 0; k < nP; ++k) {
        for (int g = 0; g < q; ++g) {
            double s = 0.5 + 0.5 * gx[g];  // fraction across the cell
            double ph = grid.phi(k) + s * dPhi;
            double dw = 0.5 * dPhi * gw[g];
            for (int m = 0; m <= L; ++m) {
                double c = m == 0 ? 1.0 : std::sqrt(2.0) * std::cos(m * ph);
                double sn = std::sqrt(2.0) * std::sin(m * ph);
                Phi(L + m, k) += c * dw * (1.0 - s);
                Phi(L + m, (k + 1) % nP) += c * dw * s;
                if (m > 0) {
                    Phi(L - m, k) += sn * dw * (1.0 - s);
                    Phi(L - m, (k + 1) % nP) += sn * dw * s;
                }
            }
        }
    }

    const int K = shEvenCount(L);
    Eigen::MatrixXd M(K, grid.count());
    for (const ShLM& f : shEvenFunctions(L)) {
        int r = shEvenIndex(f.l, f.m);
        for (int i = 0; i < nT; ++i) {
            double th = 2.0 * Theta(leg(f.l, std::abs(f.m)), i);
            for (int k = 0; k < nP; ++k) M(r, i * nP + k) = th * Phi(L + f.m, k);
        }
    }
    return M;
}

std::vector<double> gridSolidAngles(const DirectionGrid& grid) {
    std::vector<double> a(grid.count());
    for (int j = 0; j < grid.count(); ++j) a[j] = cellSolidAngle(grid, j / grid.nPhi);
    return a;
}

Eigen::MatrixXd leastSquaresMatrix(const DirectionGrid& grid, int L) {
    checkGrid(grid);
    std::vector<glm::dvec3> dirs(grid.count());
    for (int j = 0; j < grid.count(); ++j) dirs[j] = grid.direction(j);
    return leastSquaresMatrix(dirs, gridSolidAngles(grid), L);
}

Eigen::MatrixXd leastSquaresMatrix(const std::vector<glm::dvec3>& dirs, const std::vector<double>& solidAngle, int L) {
    const int K = shEvenCount(L), J = int(dirs.size());
    SHREFRACT_CHECK(J >= K && solidAngle.size() == dirs.size());
    // Minimize sum_j a_j (sum_i c_i y_i(w_j) - r_j)^2 with a_j = the solid angle w_j stands for:
    // c = (Y^T A Y)^-1 Y^T A r. Even functions on the hemisphere keep the normal matrix near I/2.
    Eigen::MatrixXd Y(J, K);
    std::vector<double> all(shCount(L));
    const std::vector<ShLM> fs = shEvenFunctions(L);
    for (int j = 0; j < J; ++j) {
        shEvalAllRecurrence(L, dirs[j], all.data());
        for (int e = 0; e < K; ++e) Y(j, e) = all[shIndex(fs[e].l, fs[e].m)];
    }
    const Eigen::Map<const Eigen::VectorXd> a(solidAngle.data(), J);
    Eigen::MatrixXd YtA = Y.transpose() * a.asDiagonal();
    Eigen::MatrixXd G = YtA * Y;
    return G.ldlt().solve(YtA);
}

CellCorners cellCorners(const DirectionGrid& grid) {
    checkGrid(grid);
    const double dTheta = 0.5 * kPi / grid.nTheta, dPhi = 2.0 * kPi / grid.nPhi;
    CellCorners c;
    for (int i = 0; i + 1 < grid.nTheta; ++i) {
        const double t = (i + 1) * dTheta;
        const double area = dPhi * (std::cos(t - 0.5 * dTheta) - std::cos(t + 0.5 * dTheta));
        for (int k = 0; k < grid.nPhi; ++k) {
            const double p = (k + 1) * dPhi;
            c.directions.push_back({std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)});
            c.solidAngle.push_back(area);
        }
    }
    return c;
}

Eigen::MatrixXd compressionMatrixCached(const DirectionGrid& grid, int L,
                                        const std::string& cacheDir) {
    return compressionMatrixCached(grid, L, cacheDir, 8);
}

Eigen::MatrixXd compressionMatrixCached(const DirectionGrid& grid, int L,
                                        const std::string& cacheDir, int q) {
    if (cacheDir.empty()) return compressionMatrix(grid, L, q);
    const std::string path = cachePath(grid, L, q, cacheDir);
    Eigen::MatrixXd M;
    if (readCache(path, grid, L, q, &M)) return M;
    M = compressionMatrix(grid, L, q);
    std::error_code ec;
    std::filesystem::create_directories(cacheDir, ec);
    if (!writeCache(path, grid, L, q, M))
        std::fprintf(stderr, "shrefract: warning: could not write cache file %s\n", path.c_str());
    return M;
}

}  // namespace shrefract
