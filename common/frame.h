// The local shading frame of a surface sample: a deterministic function of the normal alone,
// so that the bake and the runtime (GLSL twin in shaders/) cannot disagree and nothing is stored.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

namespace shrefract {

// Orthonormal basis (t, b, n) from a unit normal n: Duff et al. 2017, "Building an Orthonormal
// Basis, Revisited" (JCGT 6(1)), branchless. Right-handed: cross(t, b) = n.
struct Frame {
    glm::vec3 t, b, n;

    static Frame fromNormal(glm::vec3 n) {
        float sign = std::copysign(1.0f, n.z);
        float a = -1.0f / (sign + n.z);
        float bb = n.x * n.y * a;
        Frame f;
        f.t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * bb, -sign * n.x);
        f.b = glm::vec3(bb, sign + n.y * n.y * a, -n.y);
        f.n = n;
        return f;
    }
    // World (object space) to local: z is the normal.
    glm::vec3 toLocal(glm::vec3 v) const { return {glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)}; }
    glm::vec3 fromLocal(glm::vec3 v) const { return v.x * t + v.y * b + v.z * n; }
};

}  // namespace shrefract
