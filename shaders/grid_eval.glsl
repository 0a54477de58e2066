// The grid basis (docs/format.md "weights"): a sample's traced exits at the bake's grid
// directions, read back bilinearly. gridCorners is the GLSL twin of DirectionGrid::interpolate
// (common/direction_grid.cpp): the four grid directions around w, as weight-array layers
// j = ring * nPhi + column, and their weights (summing to 1). The generator
// (runtime/src/shadergen.cpp) defines SHREFRACT_GRID_THETA and SHREFRACT_GRID_PHI.
// w: the local view direction, z along the normal; below the tangent plane it is mirrored.
void gridCorners(vec3 w, out ivec4 index, out vec4 weight) {
    const int nT = SHREFRACT_GRID_THETA, nP = SHREFRACT_GRID_PHI;
    const float pi = 3.14159265358979;
    float rxy = length(w.xy);
    float th = atan(rxy, abs(w.z));                    // [0, pi/2]
    float ph = rxy > 0.0 ? atan(w.y, w.x) : 0.0;       // atan(0, 0) is undefined in GLSL
    if (ph < 0.0) ph += 2.0 * pi;
    // phi: columns at (k + 1/2) 2pi / nP, wrapping.
    float v = ph * float(nP) / (2.0 * pi) - 0.5;
    float kf = floor(v);
    float s = v - kf;                                  // the weight of column k1
    int k0 = (int(kf) + nP) % nP;                      // kf >= -1: no negative operand to %
    int k1 = (k0 + 1) % nP;
    // theta: rings at (i + 1/2) (pi/2) / nT.
    float u = th * float(nT) / (0.5 * pi) - 0.5;
    if (u >= float(nT - 1)) {                          // past the last ring: constant in theta
        int r = (nT - 1) * nP;
        index = ivec4(r + k0, r + k1, r + k0, r + k1);
        weight = vec4(1.0 - s, s, 0.0, 0.0);
        return;
    }
    if (u < 0.0) {                                     // the pole cap: across it at phi + pi
        int h = nP / 2;
        float t = u + 1.0;
        index = ivec4(k0, k1, (k0 + h) % nP, (k1 + h) % nP);
        weight = vec4(t * (1.0 - s), t * s, (1.0 - t) * (1.0 - s), (1.0 - t) * s);
        return;
    }
    int i0 = min(int(u), nT - 2);
    float t = u - float(i0);                           // the weight of ring i0 + 1
    index = ivec4(i0 * nP + k0, i0 * nP + k1, (i0 + 1) * nP + k0, (i0 + 1) * nP + k1);
    weight = vec4((1.0 - t) * (1.0 - s), (1.0 - t) * s, t * (1.0 - s), t * s);
}
