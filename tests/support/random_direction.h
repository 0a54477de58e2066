// A direction drawn uniformly over the sphere (a normalized 3D Gaussian), for tests that check a
// function of directions at random ones.
#pragma once

#include <random>

#include <glm/glm.hpp>

namespace shrefract::test {

inline glm::dvec3 randomDirection(std::mt19937_64& rng) {
    std::normal_distribution<double> n;
    glm::dvec3 v;
    do v = {n(rng), n(rng), n(rng)};
    while (glm::length(v) < 1e-6);
    return glm::normalize(v);
}

}  // namespace shrefract::test
