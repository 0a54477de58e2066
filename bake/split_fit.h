// A representation with an edge, measured and not built (docs/bake.md "An edge in the mapping"):
// where a sample's paths split into two classes over the view directions (TIR or not, say), the
// exit jumps at the class border, and SH bands ring across the jump. The split fit stores
//  - an indicator: the least-squares SH (order `indicatorOrder`) of 1 on the class, 0 off it;
//  - two weighted fits (order `branchOrder`, bake/fit.h), one fitted on each side of the border
//    and continued smoothly across it (confidence x kAcross there);
// and reconstructs at w from the branch on the indicator's side of 1/2, so the jump stays sharp
// wherever the indicator's level line follows the border. shrefract-fit-study measures it against
// the whole-hemisphere fit at equal bytes (scripts/study-edge).
#pragma once

#include <cstdint>

#include <Eigen/Core>
#include <glm/glm.hpp>

#include "bake/fit.h"

namespace shrefract {

struct SplitModel {
    Eigen::VectorXf indicator;  // shEvenCount(indicatorOrder): the class's indicator
    Eigen::MatrixXf branch[2];  // shEvenCount(branchOrder) x 4 each: 0 off the class, 1 on it
};

class SplitFitter {
public:
    // Confidence of a path on the other side of the border, in each branch's fit.
    static constexpr float kAcross = 1e-3f;
    // `classFlags`: a path is in the class when it has any of them. Within a branch the class is
    // no reason to doubt a path, so `weighting` drops those flags; the others still lower c_j.
    SplitFitter(const DirectionGrid& grid, int branchOrder, int indicatorOrder, uint32_t classFlags,
                FitWeighting weighting = {});
    // Floats stored per sample: four channels per branch coefficient, one per indicator's.
    int floats() const;
    // The model of one sample from its J grid paths and R (J x 4: exit x, y, z, length).
    SplitModel fit(const Eigen::Ref<const Eigen::MatrixXf>& R, const PathResult* paths) const;
    // Exit x, y, z (not normalized) and length at the unit direction w (local frame, z >= 0).
    glm::vec4 evaluate(const SplitModel& m, glm::vec3 w) const;

private:
    int J_, branchOrder_, indicatorOrder_;
    uint32_t classFlags_;
    WeightedFitter branchFitter_;
    Eigen::MatrixXf indicatorMatrix_;  // K_t x J: the least-squares fit of the indicator
};

}  // namespace shrefract
