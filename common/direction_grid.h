// The regular grid of view directions over the outer hemisphere and the compression matrix
// M_ij = ∫ y_i B_j over the sphere (paper eq. 8-10).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <glm/glm.hpp>

namespace shrefract {

// nTheta x nPhi samples at cell centres of the (theta, phi) grid over the hemisphere z >= 0 in
// the local frame (z = normal): theta_i = (i + 1/2) (pi/2) / nTheta, phi_k = (k + 1/2) 2pi / nPhi.
// Sample index j = i * nPhi + k. nPhi must be even (the pole reflection maps phi to phi + pi).
struct DirectionGrid {
    int nTheta = 32, nPhi = 64;

    int count() const { return nTheta * nPhi; }
    bool operator==(const DirectionGrid& o) const { return nTheta == o.nTheta && nPhi == o.nPhi; }
    bool operator!=(const DirectionGrid& o) const { return !(*this == o); }
    double theta(int i) const;
    double phi(int k) const;
    glm::dvec3 direction(int j) const;
    // The interpolation B_j that extends the samples to the whole sphere: bilinear in
    // (theta, phi), wrapping in phi, reflected across the pole (theta < theta_0 interpolates
    // towards the sample at phi + pi), constant past the last ring (the mirror across the
    // equator), and mirrored to z < 0 (f(x, y, -z) = f(x, y, z)). Writes up to 4 (index, weight)
    // pairs with weights summing to 1; returns how many.
    int interpolate(glm::dvec3 w, int index[4], double weight[4]) const;
    std::string ToString() const;  // "32x64"
};
// The solid angle each grid direction stands for, its (theta, phi) cell: dPhi (cos theta_lo -
// cos theta_hi). They sum to 2 pi over the hemisphere.
std::vector<double> gridSolidAngles(const DirectionGrid& grid);
// What is wrong with a grid, or "" when it is usable: counts in [limits::kMinGrid, kMaxGrid], nPhi
// even. The one check for --grid and for a bake file's manifest.
std::string gridProblem(int nTheta, int nPhi);
// Parses "32x64"; throws InputError naming `what` on bad text.
DirectionGrid parseGrid(const std::string& text, const std::string& what = "--grid");

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_q): exact for polynomials of degree
// up to 2q - 1. The quadrature behind M, and the tests' integrals over the sphere.
void gaussLegendre(int q, std::vector<double>* x, std::vector<double>* w);

// M (K x J), K = shEvenCount(L) rows in even order, J = grid.count() columns, double precision,
// by Gauss-Legendre quadrature with `q` x `q` points in every interpolation cell.
Eigen::MatrixXd compressionMatrix(const DirectionGrid& grid, int L, int q = 8);
// Least-squares alternative: K x J pseudo-inverse of the basis sampled at the grid directions
// (weighted by cell solid angle), for the projection-vs-fit comparison.
Eigen::MatrixXd leastSquaresMatrix(const DirectionGrid& grid, int L);
// The same over any directions, each weighted by the solid angle it stands for: K x dirs.size().
Eigen::MatrixXd leastSquaresMatrix(const std::vector<glm::dvec3>& dirs, const std::vector<double>& solidAngle, int L);

// The directions furthest from the grid's own: the corners of its interpolation cells inside the
// hemisphere, theta = (i + 1) (pi/2) / nTheta for i < nTheta - 1 and phi = (k + 1) 2pi / nPhi,
// corner c = i * nPhi + k, each standing for the solid angle of the cell around it. Where a bilinear
// read of the grid is least certain; none when nTheta is 1.
struct CellCorners {
    std::vector<glm::dvec3> directions;
    std::vector<double> solidAngle;
};
CellCorners cellCorners(const DirectionGrid& grid);

// compressionMatrix(), cached on disk in `cacheDir` under a name made of its parameters.
// A corrupt or mismatched cache file is recomputed and rewritten. Empty cacheDir: no cache.
Eigen::MatrixXd compressionMatrixCached(const DirectionGrid& grid, int L, const std::string& cacheDir);
// The same with an explicit quadrature resolution q (the 3-argument form uses q = 8). The file
// name is shM_L<L>_<grid>_q<q>.bin; its header (magic, L, grid, q, size, checksum) is validated.
Eigen::MatrixXd compressionMatrixCached(const DirectionGrid& grid, int L, const std::string& cacheDir,
                                        int q);

}  // namespace shrefract
