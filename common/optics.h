// Dielectric optics for the tracer and the renderers.
//
// Conventions (docs/conventions.md): directions are unit vectors; `wi` points AWAY from the
// surface, toward where the light came from (pbrt); `n` is on the same side as `wi`.
// eta = n_transmitted / n_incident (pbrt and Mitsuba; Embree's tutorial optics.h uses the
// reciprocal).
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

namespace shrefract {

// Mirror reflection of wi about n: the result points away from the surface too.
inline glm::vec3 Reflect(glm::vec3 wi, glm::vec3 n) { return -wi + 2.0f * glm::dot(wi, n) * n; }

// Refraction of wi through a surface with normal n (same side as wi), eta = n_t / n_i.
// Returns false on total internal reflection; else *wt points into the other medium.
inline bool Refract(glm::vec3 wi, glm::vec3 n, float eta, glm::vec3* wt) {
    float cosI = glm::dot(n, wi);
    float sin2I = std::max(0.0f, 1.0f - cosI * cosI);
    float sin2T = sin2I / (eta * eta);  // Snell: sinT = sinI / eta
    if (sin2T >= 1.0f) return false;
    float cosT = std::sqrt(1.0f - sin2T);
    *wt = -wi / eta + (cosI / eta - cosT) * n;
    return true;
}

// Unpolarized Fresnel reflectance of a dielectric interface, cosI = cos of the incident angle
// (>= 0), eta = n_t / n_i. Returns 1 on total internal reflection.
inline float FresnelDielectric(float cosI, float eta) {
    cosI = std::clamp(cosI, 0.0f, 1.0f);
    float sin2T = (1.0f - cosI * cosI) / (eta * eta);
    if (sin2T >= 1.0f) return 1.0f;
    float cosT = std::sqrt(1.0f - sin2T);
    float rParl = (eta * cosI - cosT) / (eta * cosI + cosT);
    float rPerp = (cosI - eta * cosT) / (cosI + eta * cosT);
    return 0.5f * (rParl * rParl + rPerp * rPerp);
}

}  // namespace shrefract
