// common/prefilter.h resultantOfSigma: the mean resultant length coth(kappa) - 1 / kappa of the
// vMF lobe with kappa = 1 / sigma^2, how the bake's predicted error rides in the length of the
// exit vector (shaders/error_fold.frag, shaders/web_shade.vert; shading.glsl spreadSigma reads
// it back).
float resultantOfSigma(float sigma) {
    if (sigma < 1e-3) return 1.0;  // kappa > 1e6: within float rounding of 1
    float kappa = 1.0 / (sigma * sigma);
    float e = exp(-2.0 * kappa);
    return (1.0 + e) / (1.0 - e) - 1.0 / kappa;
}
