// The shading every method shares (included by shade.frag, baseline.frag, background.frag), so
// SH, the baselines and the background differ only in the exit direction and length they pass
// in. Twins: common/optics.h (Fresnel), common/tonemap.h (tone map).
// common/optics.h FresnelDielectric: unpolarized, eta = n_t / n_i, 1 on TIR.
float fresnelDielectric(float cosI, float eta) {
    cosI = clamp(cosI, 0.0, 1.0);
    float sin2T = (1.0 - cosI * cosI) / (eta * eta);
    if (sin2T >= 1.0) return 1.0;
    float cosT = sqrt(1.0 - sin2T);
    float rParl = (eta * cosI - cosT) / (eta * cosI + cosT);
    float rPerp = (cosI - eta * cosT) / (cosI + eta * cosT);
    return 0.5 * (rParl * rParl + rPerp * rPerp);
}

// common/tonemap.h: exposure, the ACES fit of Narkowicz 2015, sRGB encoding.
vec3 toneMap(vec3 c, float exposure) {
    c *= exposure;
    c = clamp((c * (2.51 * c + 0.03)) / (c * (2.43 * c + 0.59) + 0.14), 0.0, 1.0);
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

// Front-surface Fresnel reflection plus the transmitted environment along the exit direction,
// attenuated by exp(-kappa * length). n: unit normal, v: unit direction toward the viewer.
vec3 shadeGlass(samplerCube env, vec3 exitDir, float len, vec3 n, vec3 v, float eta, vec3 kappa) {
    float F = fresnelDielectric(dot(n, v), eta);
    vec3 transmitted = texture(env, exitDir).rgb * exp(-kappa * max(len, 0.0));
    vec3 reflected = texture(env, reflect(-v, n)).rgb;
    return F * reflected + (1.0 - F) * transmitted;
}
