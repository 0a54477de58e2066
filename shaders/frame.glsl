// The local shading frame of a sample, a function of its unit normal alone: common/frame.h
// (Duff et al. 2017, branchless orthonormal basis), ported operation for operation.

// Local coordinates (v . t, v . b, v . n) of v in the frame of the unit normal n: z is the normal.
vec3 toLocalFrame(vec3 v, vec3 n) {
    // std::copysign(1, n.z): the sign bit decides, so -0.0 gives -1 as on the CPU.
    float sgn = (floatBitsToUint(n.z) & 0x80000000u) != 0u ? -1.0 : 1.0;
    float a = -1.0 / (sgn + n.z);
    float bb = n.x * n.y * a;
    vec3 t = vec3(1.0 + sgn * n.x * n.x * a, sgn * bb, -sgn * n.x);
    vec3 b = vec3(bb, sgn + n.y * n.y * a, -n.y);
    return vec3(dot(v, t), dot(v, b), dot(v, n));
}
