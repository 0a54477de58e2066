// The bake's error model on the GPU (docs/runtime.md "Error model"): after decompression, one
// pass over the mu layout evaluates each sample's predicted angular error at its local view
// direction and sets the length of its exit vector to the matching vMF resultant length
// (shaders/error_fold.frag), so that the spread shading's lobe comes from the prediction.
#pragma once

#include <functional>
#include <string>

#include "common/bakefile.h"
#include "gl.h"

namespace shrefract {

class ErrorFold {
public:
    // Uploads the bake's error model (BakeData::errors, errorOrder >= 0) as an R16F array, one
    // layer per coefficient, and compiles the pass. `texelOf[i]`: sample i's mu texel. The pass
    // links with `vertexShader`, the one its `draw` needs (the pipeline's, as the decompression
    // passes do): a full-screen triangle drawn per chart triangle would shade the whole layout
    // once for every triangle of the mesh.
    ErrorFold(const BakeData& bake, const std::vector<size_t>& texelOf,
              const std::string& vertexShader);
    ~ErrorFold();
    ErrorFold(const ErrorFold&) = delete;
    ErrorFold& operator=(const ErrorFold&) = delete;

    // D_mu with the error folded in, into this pass's own RGBA32F target (returned). `draw`
    // covers the samples (a full-screen triangle, or the charts' footprint); the caller has set
    // the viewport to the mu layout and bound an empty vertex array.
    unsigned apply(unsigned d, unsigned localView, const std::function<void()>& draw);
    size_t bytes() const { return bytes_; }  // the error layers and the target

private:
    int width_, height_;
    unsigned errors_ = 0, program_ = 0;
    gl::Target target_;
    size_t bytes_ = 0;
};

}  // namespace shrefract
