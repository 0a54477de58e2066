// The ranges every way into a bake accepts, in one place: shrefract-bake's options, a scene file's
// media, and the manifest of a bake file read back (manifestProblem, common/bake_validate.cpp).
// What the bake refuses to make, the reader refuses to load.
#pragma once

namespace shrefract::limits {

constexpr double kMinIor = 1.0;  // below 1 is not a dielectric we trace
constexpr double kMaxIor = 5.0;  // well past diamond (2.42) and rutile (2.9): likely a typo
constexpr int kMaxOrder = 20;    // 231 coefficients: GL 3.3 guarantees 256 array layers
constexpr int kMaxErrorOrder = 8;  // 45 coefficients: one R16F layer each in the runtime
constexpr int kMaxRate = 64;     // grid steps per triangle edge (2145 samples per triangle)
constexpr int kMaxBounces = 10000;
constexpr double kMaxFilterWidth = 1000.0;  // bands
constexpr int kMinGrid = 2, kMaxGrid = 1024;  // directions per axis of the hemisphere grid
constexpr int kMaxGridBasis = 2048;  // directions of a grid-basis bake: GL 4.5's array layers
constexpr int kMaxTextureSize = 32768;        // any side of the mu, rho or neighbour-list parts

}  // namespace shrefract::limits
