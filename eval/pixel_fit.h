// A bake's direction representation at unlimited sample density (docs/evaluation.md "Pixel
// fits"): at every pixel's entry point the ray tracer traces the bake's whole direction grid,
// fits it there as the bake fits a sample, and shades with the fit's exit at the pixel's own view
// direction. No sample spacing, no interpolation over the surface, no quantization and no spread:
// what the image still lacks against the traced truth is the representation's own error. It is how
// a representation the runtime does not draw (the split fit, bake/split_fit.h) is judged in
// image space, beside the one it does (`shrefract-render --method raytrace --exits`).
#pragma once

#include <memory>
#include <string>

#include "bake/fit.h"
#include "bake/split_fit.h"
#include "common/bakefile.h"
#include "eval/reference.h"
#include "shrefract/enum_names.h"

namespace shrefract {

enum class PixelExits {
    Exact,  // the traced path itself (the reference)
    Fit,    // the bake's own fit (fit, order, weighting, band filter from its manifest)
    Split,  // the split fit 8:8 of the TIR paths, where it fits the grid better than Fit
    Grid,   // the raw grid interpolated bilinearly: the data's ceiling
};
template <> struct EnumNames<PixelExits> {
    static constexpr const char* what = "exits";
    static constexpr NamedValue<PixelExits> table[] = {{PixelExits::Exact, "exact"},
                                                       {PixelExits::Fit, "fit"},
                                                       {PixelExits::Split, "split"},
                                                       {PixelExits::Grid, "grid"}};
};

class PixelFit : public ExitSource {
public:
    // The split's branch and indicator orders (docs/bake.md "An edge in the mapping": 8:8 with
    // the pick halves the mug's TIR error at 8 % more floats than the default order 12).
    static constexpr int kSplitBranchOrder = 8, kSplitIndicatorOrder = 8;

    // `kind` != Exact; the fit's settings are the bake's (its manifest: grid, order, fit,
    // fitWeighting, filterWidth). Throws InputError when the manifest lacks them.
    PixelFit(const BakeData& bake, PixelExits kind);
    ~PixelFit() override;
    PathResult exit(const Tracer& tracer, glm::vec3 p, glm::vec3 n, glm::vec3 omega,
                    int part) const override;

private:
    PixelExits kind_;
    DirectionGrid grid_;
    int order_ = 0;
    std::unique_ptr<SampleFit> fit_;
    std::unique_ptr<WeightedFitter> confidence_;  // Split: the pick's weights
    std::unique_ptr<SplitFitter> split_;
};

}  // namespace shrefract
