// The shading library every method's fragment shader includes (shaders/shading.glsl), run on the
// GPU and held to closed forms computed here in double precision: the front-surface Fresnel that
// shadeGlass() weights the reflection with, and the tone map. The C++ twins (common/optics.h,
// common/tonemap.h) are held to the same closed forms in tests/common/optics_test.cpp.
#include <gtest/gtest.h>

#include <cmath>

#include "gl.h"
#include "shaders.h"
#include "shrefract/context.h"
#include "shrefract/render.h"
#include "shrefract/runtime.h"

namespace shrefract {
namespace {

using namespace gl;

constexpr double kPi = 3.14159265358979323846;
constexpr int kColumns = 16;

// The program: column i of row 0 shades glass (eta = uEta) seen at 75 i / 15 degrees from the
// normal, with the reflection looking into a white sky and the transmitted ray into a black
// ground, so that the colour is the Fresnel reflectance F. Row 1 tone maps (x, x/3, 3x) for
// x = 2^(i/2 - 5). Row 2 looks straight down the normal with both rays in the sky, through a path
// of length i / 10 absorbing (0.5, 1, 2) per unit: F(0) + (1 - F(0)) exp(-kappa length).
// Sharp lookups (lobe widths 0) throughout.
const char* kMain = R"(
uniform float uEta;
layout(location = 0) out vec4 oColor;
void main() {
    float i = floor(gl_FragCoord.x);
    if (gl_FragCoord.y < 1.0) {
        float theta = radians(75.0 * i / 15.0);
        vec3 n = vec3(0.0, 1.0, 0.0), v = vec3(sin(theta), cos(theta), 0.0);
        oColor = vec4(shadeGlass(vec3(0.0, -1.0, 0.0), 0.0, 0.0, n, v, uEta, vec3(0.0), 0.0), 1.0);
    } else if (gl_FragCoord.y > 2.0) {
        vec3 n = vec3(0.0, 1.0, 0.0);
        oColor = vec4(shadeGlass(n, 0.0, i / 10.0, n, n, uEta, vec3(0.5, 1.0, 2.0), 0.0), 1.0);
    } else {
        float x = exp2(i / 2.0 - 5.0);
        oColor = vec4(toneMap(vec3(x, x / 3.0, 3.0 * x), 1.0), 1.0);
    }
}
)";

// Unpolarized Fresnel reflectance from air into a medium of index eta, from the angles.
double fresnel(double thetaI, double eta) {
    if (thetaI == 0.0) return std::pow((eta - 1) / (eta + 1), 2);
    const double thetaT = std::asin(std::sin(thetaI) / eta);
    return 0.5 * (std::pow(std::sin(thetaI - thetaT) / std::sin(thetaI + thetaT), 2) +
                  std::pow(std::tan(thetaI - thetaT) / std::tan(thetaI + thetaT), 2));
}

// The documented tone map: the ACES fit of Narkowicz 2015, clamped, then sRGB.
double toneMapped(double x) {
    double y = std::min(1.0, std::max(0.0, (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)));
    return y <= 0.0031308 ? 12.92 * y : 1.055 * std::pow(y, 1 / 2.4) - 0.055;
}

class ShadingGlsl : public ::testing::TestWithParam<Backend> {
protected:
    void SetUp() override {
        try {
            context_ = createHeadlessContext(GetParam(), kColumns, 3);
        } catch (const ContextError& e) {
            GTEST_SKIP() << "no " << nameOf(GetParam()) << " context: " << e.what();
        }
    }
    std::unique_ptr<HeadlessContext> context_;
};

// Measured on llvmpipe: |GPU - closed form| <= 2e-7 for F, <= 4e-7 for the tone map (float32),
// absorption alike.
// Thresholds 1e-5: float rounding, far below what a wrong constant or eta changes (F with 1/eta
// is 1 past 42 degrees; a tone-map constant off by 0.01 moves values by >= 1e-3).
TEST_P(ShadingGlsl, FresnelAbsorptionAndToneMapMatchTheirClosedForms) {
    ensureLoaded(context_->loader());
    // Sky white above the horizon, ground black below it (lat-long, row 0 at +y).
    const int w = 256, h = 128;
    std::vector<float> rgb(size_t(w) * h * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) rgb[(size_t(y) * w + x) * 3 + c] = y < h / 2 ? 1.0f : 0.0f;
    Environment env = Environment::fromLatLong(w, h, rgb);
    const std::string fragment = "#version 330 core\n" + shaders::source("shading.glsl") + kMain;
    GLuint program = buildProgram(shaders::source("fullscreen.vert"), fragment, "shading test");
    GLuint vao = 0;
    glGenVertexArrays(1, &vao);
    OffscreenTarget target(kColumns, 3);
    target.bind();
    glDisable(GL_DEPTH_TEST);
    glUseProgram(program);
    glUniform1i(glGetUniformLocation(program, "uEnvironment"), 0);
    glUniform1f(glGetUniformLocation(program, "uEnvironmentFaceSize"), float(env.faceSize()));
    glUniform1f(glGetUniformLocation(program, "uEnvironmentLevels"), float(env.levels()));
    glUniform1f(glGetUniformLocation(program, "uEta"), 1.5f);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_CUBE_MAP, env.cubeMap());
    glBindVertexArray(vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    const RenderedFrame f = target.read();  // rows top-down: row 0 is gl_FragCoord.y = 2.5
    glDeleteVertexArrays(1, &vao);
    glDeleteProgram(program);

    double worstF = 0, worstT = 0, worstA = 0;
    const double f0 = fresnel(0.0, 1.5), kappa[3] = {0.5, 1.0, 2.0};
    for (int i = 0; i < kColumns; ++i) {
        const float* fres = &f.color[(size_t(2) * kColumns + i) * 4];
        const float* tone = &f.color[(size_t(1) * kColumns + i) * 4];
        const float* absorbed = &f.color[size_t(i) * 4];
        for (int c = 0; c < 3; ++c) {
            const double expected = f0 + (1 - f0) * std::exp(-kappa[c] * i / 10.0);
            EXPECT_NEAR(absorbed[c], expected, 1e-5) << "length " << i / 10.0 << " channel " << c;
            worstA = std::max(worstA, std::abs(absorbed[c] - expected));
        }
        const double expectedF = fresnel(75.0 * i / 15.0 * kPi / 180, 1.5);
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(fres[c], expectedF, 1e-5) << "theta " << 75.0 * i / 15.0 << " deg";
            worstF = std::max(worstF, std::abs(fres[c] - expectedF));
        }
        const double x = std::exp2(i / 2.0 - 5.0), in[3] = {x, x / 3, 3 * x};
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(tone[c], toneMapped(in[c]), 1e-5) << "x " << in[c];
            worstT = std::max(worstT, std::abs(tone[c] - toneMapped(in[c])));
        }
    }
    std::printf("[%s] max |GPU - closed form|: Fresnel %.2g, tone map %.2g, absorption %.2g\n",
                nameOf(GetParam()), worstF, worstT, worstA);
}

INSTANTIATE_TEST_SUITE_P(Backends, ShadingGlsl, ::testing::Values(Backend::Egl, Backend::OSMesa),
                         [](const auto& info) { return std::string(nameOf(info.param)); });

}  // namespace
}  // namespace shrefract
