// The weighted least-squares fit of `--fit weighted` (docs/bake.md "Fits"): it spends each
// sample's SH bands on the view directions whose paths the bands can follow.
//
// Per sample, with a_j the solid angle of grid cell j and c_j in (0, 1] the confidence of the
// path traced along direction j,
//   W = argmin_W  sum_j a_j c_j |sum_k W_k y_k(w_j) - r_j|^2  +  ridge sum_k l_k (l_k + 1) |W_k|^2
// for the four channels of r (exit x, y, z, length) at once; c_j = 1 everywhere and ridge 0 is
// the plain least-squares fit (`--fit lsq`). The confidence is the product of what the bake
// knows about each direction:
//  - its path's flags: total internal reflection, re-entry or the bounce cap: c_j *= `flagged`;
//  - its neighbours: where the exit turns by more than `disagreeDeg` to a grid neighbour's, the
//    mapping changes faster than the grid samples it: c_j is at most `disagreeing`;
//  - the fit itself (`trimPasses` times): where a fit misses r_j by more than `trimDeg`, the bands
//    cannot follow that direction: c_j *= `trimmed`, and the sample is fitted again.
// Fitting the chaotic directions closely rings over the whole hemisphere; down-weighted, the bands
// follow the learnable part (measured by scripts/fit-study; docs/bake.md "Fits").
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "bake/tracer.h"
#include "common/direction_grid.h"
#include "shrefract/enum_names.h"

namespace shrefract {

// How each sample's grid of traced paths becomes SH weights (docs/bake.md "Fits").
enum class Fit {
    Projection,    // W = M R through the compression matrix (paper eq. 10)
    LeastSquares,  // solid-angle-weighted least squares on the grid samples
    Weighted,      // least squares weighted by each path's confidence (below)
};
template <> struct EnumNames<Fit> {
    static constexpr const char* what = "fit";
    static constexpr NamedValue<Fit> table[] = {
        {Fit::Projection, "projection"}, {Fit::LeastSquares, "lsq"}, {Fit::Weighted, "weighted"}};
};

// Whether `fit` can make order L from `grid`'s directions: the least-squares fits solve for the
// coefficients from the directions, so they need at least as many; the projection does not.
bool fitCanSolve(Fit fit, int L, const DirectionGrid& grid);

// The stored functions' band l, for the filter: even order k -> l.
std::vector<int> evenBands(int L);

struct FitWeighting {
    float flagged = 0.3f;  // c_j factor of a path with one of `flags`
    uint32_t flags = kPathTIR | kPathReentered | kPathCapped;
    float disagreeDeg = 30.0f;  // <= 0: no neighbour test
    float disagreeing = 0.01f;  // c_j at most this where the exit turns more than disagreeDeg
    float trimDeg = 10.0f;      // a fitted direction this far off is trimmed...
    float trimmed = 0.03f;      // ...c_j times this...
    int trimPasses = 2;         // ...and the sample fitted again, this many times (0: none)
    float ridge = 0.0f;         // Tikhonov weight on band l: ridge * l (l + 1)

    // No weighting at all: the plain least-squares fit.
    static FitWeighting none();
    // "FLAGGED:DEG:DISAGREEING:TRIMDEG:TRIMMED:PASSES[:RIDGE]" (the
    // defaults are "0.3:30:0.01:10:0.03:2"); throws InputError naming `what` on bad text.
    static FitWeighting parse(const std::string& text, const std::string& what = "--fit-weighting");
    std::string ToString() const;
};

// The fit a bake's manifest (or a shard's identity) records: "fit", the weighted fit's
// "fitWeighting" and "filterWidth" (absent: the projection, unfiltered). Throws InputError on a
// bad value.
struct RecordedFit {
    Fit fit = Fit::Projection;
    FitWeighting weighting;
    double filterWidth = 0.0;
};
RecordedFit recordedFit(const nlohmann::json& manifest);

// Fits one sample at a time; build once per (grid, order, weighting), use from many threads.
class WeightedFitter {
public:
    WeightedFitter(const DirectionGrid& grid, int order, const FitWeighting& weighting);
    // Any other functions, given by their values at the grid directions (J x K; `ridge` is
    // ignored: it is defined by the SH bands): the learned basis of shrefract-fit-study.
    WeightedFitter(const DirectionGrid& grid, Eigen::MatrixXf basisAtGrid, const FitWeighting& weighting);
    int coefficients() const { return int(Y_.cols()); }
    int directions() const { return int(Y_.rows()); }
    // c_j of one sample's J paths from their flags and exits (before any trim pass), into c[0..J).
    void confidence(const PathResult* paths, float* c) const;
    // W (K x 4, column c = channel) from R (J x 4, column c = channel: exit x, y, z, length at
    // grid direction j) and the confidences c, trim passes included.
    void fit(const Eigen::Ref<const Eigen::MatrixXf>& R, const float* c,
             Eigen::Ref<Eigen::MatrixXf> W) const;

private:
    // G -= sum_j a_j (from_j - to_j) y_j y_j^T over the directions whose confidence drops
    // from `from` to `to` (G's lower triangle; the others cost nothing).
    void lowerConfidence(Eigen::MatrixXf& G, const float* from, const float* to) const;
    // W from G = Y^T diag(a c) Y + diag(ridge) (lower triangle), R and the same c.
    void solve(const Eigen::MatrixXf& G, const Eigen::Ref<const Eigen::MatrixXf>& R, const float* c,
               Eigen::Ref<Eigen::MatrixXf> W) const;
    DirectionGrid grid_;
    FitWeighting weighting_;
    Eigen::MatrixXf Y_;     // J x K: the stored functions at the grid directions
    Eigen::VectorXf a_;     // J: cell solid angles
    Eigen::MatrixXf Gall_;  // K x K: Y^T diag(a) Y, every direction at confidence 1
    Eigen::VectorXf ridge_; // K: ridge * l (l + 1)
};

// Weights W (shEvenCount(L) x 4) evaluated at the unit direction w: exit x, y, z, length.
glm::vec4 evaluateFit(int L, const Eigen::Ref<const Eigen::MatrixXf>& W, glm::vec3 w);

// A bake's fit: traced exits to stored weights at one order, by `fit` (with `weighting` for the
// weighted fit) and then the semi-Gaussian band filter of `filterWidth` bands (<= 0: none). The
// bake (bake.cpp) and the --target-error / --budget search (target.cpp) both fit through it, so the
// search scores exactly the weights the bake would store. Projection and least squares are one
// GEMM per batch, W^T = R^T M^T, with the filter folded into M's rows (diag(h) (M R) =
// (diag(h) M) R); the weighted fit solves per sample and filters its solution. Build once, use
// from many threads.
class SampleFit {
public:
    SampleFit(const DirectionGrid& grid, int order, Fit fit, const FitWeighting& weighting,
              double filterWidth, const std::string& cacheDir);
    ~SampleFit();
    int coefficients() const { return K_; }
    // Whether fit() reads the paths (the weighted fit's confidences); the others take nullptr.
    bool needsPaths() const { return fitter_ != nullptr; }
    // Wt (4B x K, sample s in rows 4s..4s+3: exit x, y, z, length) from R (J x 4B, sample s in
    // columns 4s..4s+3) and, when needsPaths(), the B samples' paths (paths[s * J + j]).
    void fit(const Eigen::Ref<const Eigen::MatrixXf>& R, const PathResult* paths, int B,
             Eigen::Ref<Eigen::MatrixXf> Wt) const;

private:
    int K_;
    std::vector<float> h_;                   // the filter of each stored coefficient
    std::unique_ptr<WeightedFitter> fitter_;  // Fit::Weighted
    Eigen::MatrixXf Mt_;                     // the others: M^T (J x K), filter folded in
};

}  // namespace shrefract
