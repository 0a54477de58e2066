// shaders/sh_eval.glsl, the loop-form even-parity SH the web material evaluates per vertex with
// the order as a uniform (shaders/web_shade.vert), run on the GPU (EGL, llvmpipe here) and held
// to common/sh.cpp's double-precision Legendre recurrence (shEvalRecurrence, with atan2, cos and
// sin: no (x + iy)^m, no Q_l^m) at random unit directions over the whole sphere, orders 0..8.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "common/sh.h"
#include "gl.h"
#include "shaders.h"
#include "shrefract/render.h"
#include "support/headless.h"

namespace shrefract {
namespace {

using namespace gl;

constexpr int kWidth = 64, kHeight = 16;  // one direction per pixel

// Pixel (x, y) evaluates every function through uOrder at the direction in uDirections there and
// writes y_{uFirst..uFirst+3} (shEvalEven leaves 0 past the order's count).
const char* kMain = R"(
uniform sampler2D uDirections;
uniform int uOrder;
uniform int uFirst;
layout(location = 0) out vec4 oValues;
void main() {
    vec3 w = texelFetch(uDirections, ivec2(gl_FragCoord.xy), 0).xyz;
    float y[SHREFRACT_SH_MAX_COUNT];
    shEvalEven(uOrder, w, y);
    vec4 v = vec4(0.0);
    for (int c = 0; c < 4; ++c)
        if (uFirst + c < SHREFRACT_SH_MAX_COUNT) v[c] = y[uFirst + c];
    oValues = v;
}
)";

class ShEvalGlsl : public test::EglTest<kWidth> {};

// Measured on llvmpipe: max |GPU - double| 4.4e-6 over orders 0..8 (values up to ~1.5, the
// recurrence's float rounding growing with l). The threshold 2e-5 is 4.5x that, while a wrong
// recurrence coefficient, sign, index or missing sqrt2 moves values by 1e-2 and more.
TEST_F(ShEvalGlsl, MatchesCommonShAtRandomDirectionsThroughOrder8) {
    ensureLoaded(context_->loader());
    std::mt19937 rng(19);
    std::normal_distribution<double> gauss;
    std::vector<glm::dvec3> dirs(size_t(kWidth) * kHeight);
    std::vector<float> texels(dirs.size() * 4);
    for (size_t i = 0; i < dirs.size(); ++i) {
        glm::dvec3 d(gauss(rng), gauss(rng), gauss(rng));
        if (i == 0) d = {0, 0, 1};   // the poles, where sin theta = 0
        if (i == 1) d = {0, 0, -1};
        const glm::vec3 unit = glm::normalize(glm::vec3(glm::normalize(d)));
        dirs[i] = glm::dvec3(unit);  // the reference at the very floats the GPU reads
        for (int c = 0; c < 3; ++c) texels[i * 4 + c] = unit[c];
    }
    const std::string fragment = "#version 330 core\n" + shaders::source("sh_eval.glsl") + kMain;
    GLuint program = buildProgram(shaders::source("fullscreen.vert"), fragment, "sh_eval test");
    GLuint directions = makeTexture2D(GL_RGBA32F, kWidth, kHeight, GL_RGBA, GL_FLOAT, texels.data(), GL_NEAREST);
    GLuint vao = 0;
    glGenVertexArrays(1, &vao);
    OffscreenTarget target(kWidth, kHeight);
    double worst = 0;
    for (int L = 0; L <= 8; ++L) {
        const std::vector<ShLM> functions = shEvenFunctions(L);
        const int K = static_cast<int>(functions.size());
        for (int first = 0; first < K; first += 4) {
            target.bind();
            glDisable(GL_DEPTH_TEST);
            glUseProgram(program);
            glActiveTexture(GL_TEXTURE0);
            glBindTexture(GL_TEXTURE_2D, directions);
            glUniform1i(glGetUniformLocation(program, "uDirections"), 0);
            glUniform1i(glGetUniformLocation(program, "uOrder"), L);
            glUniform1i(glGetUniformLocation(program, "uFirst"), first);
            glBindVertexArray(vao);
            glDrawArrays(GL_TRIANGLES, 0, 3);
            const RenderedFrame f = target.read();  // rows top-down
            for (int y = 0; y < kHeight; ++y)
                for (int x = 0; x < kWidth; ++x) {
                    const glm::dvec3 d = dirs[size_t(y) * kWidth + x];
                    const float* got = &f.color[(size_t(kHeight - 1 - y) * kWidth + x) * 4];
                    for (int c = 0; c < 4; ++c) {
                        const int k = first + c;
                        const double want = k < K ? shEvalRecurrence(functions[k].l, functions[k].m, d) : 0.0;
                        ASSERT_NEAR(got[c], want, 2e-5)
                            << "order " << L << " y_" << (k < K ? functions[k].l : -1) << "^"
                            << (k < K ? functions[k].m : 0) << " at (" << d.x << ", " << d.y << ", " << d.z << ")";
                        worst = std::max(worst, std::abs(got[c] - want));
                    }
                }
        }
    }
    glDeleteVertexArrays(1, &vao);
    glDeleteTextures(1, &directions);
    glDeleteProgram(program);
    std::printf("sh_eval.glsl orders 0..8: max |GPU - common/sh.cpp| %.2g\n", worst);
}

}  // namespace
}  // namespace shrefract
