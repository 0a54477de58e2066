// Shading at other indices of refraction than the bake's, one per RGB channel (paper §5.4;
// docs/runtime.md "Variable IOR and dispersion"). Refractor::draw() switches to this when
// setIor() was called: shaders/shade_ior.frag instead of shade.frag, on either path.
#pragma once

#include <glm/glm.hpp>

#include "gl.h"

namespace shrefract {

class Refractor;

// Interpolation weight per channel between direction a at index nA and b at index nB, for the
// index n: t = (n - nA) / (nB - nA). The paper's §5.4 is a = the straight path, nA = 1.
glm::vec3 iorBlendWeights(glm::vec3 ior, float nA, float nB);

struct IorShading {
    bool active = false;
    glm::vec3 ior{1.5f};
    Refractor* bracket = nullptr;  // second bake (mode 2), updated with the refractor
    GLuint bracketD = 0;           // its D for this frame: D_mu (direct path) or rho (rho path)
    GLuint rhoProgram = 0, directProgram = 0;  // built on first use

    // The program draw() uses on the rho or the direct path (D_mu fetched per vertex: the
    // texture-space decompression, never the vertex-shader one), building it on first use.
    GLuint program(bool direct, int muWidth);
    // The uniforms beyond shade.frag's (which draw() sets as usual) on the current program
    // `p`, and the bracket's D on texture unit 5. `bakeIor`: this refractor's bake's index.
    void setUniforms(GLuint p, float bakeIor, float bracketIor) const;
    void destroy();
};

}  // namespace shrefract
