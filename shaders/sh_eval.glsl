// The even-parity real SH of common/sh.cpp shEvalEven, in loop form for shaders that take the
// order at run time (the web material, shaders/web_shade.vert): the normalized associated
// Legendre recurrence on Q_l^m = Pbar_l^m / sin^m theta, times Re/Im (x + iy)^m, so no
// trigonometry and no division by sin theta. Same convention (docs/conventions.md: no
// Condon-Shortley phase, orthonormal) and even order (k = l(l+1)/2 + (m+l)/2) as the bake file;
// runtime/src/shadergen.cpp unrolls the same recurrence per order for the C++ runtime.
// tests/runtime/sh_eval_test.cpp holds it to common/sh.cpp at orders 0..8.
#ifndef SHREFRACT_SH_MAX_ORDER
#define SHREFRACT_SH_MAX_ORDER 8
#endif
#define SHREFRACT_SH_MAX_COUNT ((SHREFRACT_SH_MAX_ORDER + 1) * (SHREFRACT_SH_MAX_ORDER + 2) / 2)

// y[k] = y_k(w) for the (L+1)(L+2)/2 even functions through order L (<= SHREFRACT_SH_MAX_ORDER),
// 0 above; w a unit vector.
void shEvalEven(int L, vec3 w, out float y[SHREFRACT_SH_MAX_COUNT]) {
    for (int k = 0; k < SHREFRACT_SH_MAX_COUNT; ++k) y[k] = 0.0;
    float re = 1.0, im = 0.0;            // (x + iy)^m
    float qmm = 0.28209479177387814;     // Q_m^m = prod_{k<=m} sqrt((2k+1)/(2k)) / sqrt(4 pi)
    for (int m = 0; m <= SHREFRACT_SH_MAX_ORDER; ++m) {
        if (m > L) break;
        if (m > 0) {
            float r = re * w.x - im * w.y;
            im = re * w.y + im * w.x;
            re = r;
            qmm *= sqrt(float(2 * m + 1) / float(2 * m));
        }
        float c = m == 0 ? 1.0 : 1.41421356 * re, s = 1.41421356 * im;
        float q2 = 0.0, q1 = 0.0;  // Q_{l-2}^m, Q_{l-1}^m
        for (int l = m; l <= SHREFRACT_SH_MAX_ORDER; ++l) {
            if (l > L) break;
            float q;
            if (l == m) {
                q = qmm;
            } else if (l == m + 1) {
                q = sqrt(float(2 * m + 3)) * w.z * qmm;
            } else {
                float a = sqrt(float(4 * l * l - 1) / float(l * l - m * m));
                float b = sqrt(float((l - 1) * (l - 1) - m * m) / float(4 * (l - 1) * (l - 1) - 1));
                q = a * (w.z * q1 - b * q2);
            }
            q2 = q1;
            q1 = q;
            if (((l - m) & 1) == 0) {  // even parity: l + m even
                int k = l * (l + 1) / 2 + (l + m) / 2;
                y[k] = q * c;
                if (m > 0) y[l * (l + 1) / 2 + (l - m) / 2] = q * s;
            }
        }
    }
}
