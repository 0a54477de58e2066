// Fresnel, refraction and the tone map against closed forms written out here in double precision,
// independently of common/optics.h and common/tonemap.h (the tracer's closed-form sphere uses the
// same functions it tests, so it cannot catch a wrong Fresnel).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/optics.h"
#include "common/tonemap.h"

namespace shrefract {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The Fresnel equations for unpolarized light, from the angles (Born & Wolf): incidence thetaI,
// refraction thetaT by Snell, n1 sin(thetaI) = n2 sin(thetaT).
double fresnelFromAngles(double thetaI, double n1, double n2) {
    const double s = n1 / n2 * std::sin(thetaI);
    if (s >= 1.0) return 1.0;  // total internal reflection
    const double thetaT = std::asin(s);
    if (thetaI == 0.0) return std::pow((n1 - n2) / (n1 + n2), 2);
    const double rs = std::pow(std::sin(thetaI - thetaT) / std::sin(thetaI + thetaT), 2);
    const double rp = std::pow(std::tan(thetaI - thetaT) / std::tan(thetaI + thetaT), 2);
    return 0.5 * (rs + rp);
}

// At normal incidence from air into glass of 1.5: ((1.5 - 1) / (1.5 + 1))^2 = 0.04 exactly, and the
// same from inside.
TEST(Optics, FresnelAtNormalIncidenceIsFourPercentForGlass) {
    EXPECT_NEAR(FresnelDielectric(1.0f, 1.5f), 0.04f, 1e-6f);
    EXPECT_NEAR(FresnelDielectric(1.0f, 1.0f / 1.5f), 0.04f, 1e-6f);
    EXPECT_NEAR(FresnelDielectric(1.0f, 2.42f), std::pow(1.42 / 3.42, 2), 1e-6);  // diamond
    EXPECT_NEAR(FresnelDielectric(1.0f, 1.0f), 0.0f, 1e-7f);                       // no interface
}

// Brewster's angle, tan(thetaB) = eta: the parallel polarization is not reflected at all, so the
// unpolarized reflectance is half the perpendicular one, sin^2(thetaB - thetaT) / 2 with
// thetaB + thetaT = 90 degrees.
TEST(Optics, FresnelAtBrewstersAngleIsHalfThePerpendicularReflectance) {
    for (double eta : {1.33, 1.5, 2.42}) {
        const double thetaB = std::atan(eta), thetaT = kPi / 2 - thetaB;
        const double expected = 0.5 * std::pow(std::sin(thetaB - thetaT), 2);
        EXPECT_NEAR(FresnelDielectric(float(std::cos(thetaB)), float(eta)), expected, 2e-6) << eta;
        // From inside, Brewster's angle is the refracted one.
        EXPECT_NEAR(FresnelDielectric(float(std::cos(thetaT)), float(1 / eta)), expected, 2e-6) << eta;
    }
}

// Past the critical angle asin(1 / eta) from inside, everything reflects: F = 1.
TEST(Optics, FresnelIsOnePastTheCriticalAngle) {
    for (double eta : {1.33, 1.5, 2.42}) {
        const double critical = std::asin(1 / eta);
        for (double past : {0.001, 0.1, 0.5}) {
            const double theta = critical + past * (kPi / 2 - critical);
            EXPECT_EQ(FresnelDielectric(float(std::cos(theta)), float(1 / eta)), 1.0f) << eta;
        }
        // Just before it, less than 1.
        EXPECT_LT(FresnelDielectric(float(std::cos(critical - 0.01)), float(1 / eta)), 1.0f);
    }
}

// Reciprocity: the reflectance is the same from both sides of the interface along the two
// directions Snell's law pairs; and every angle matches the Fresnel equations from the angles.
TEST(Optics, FresnelIsReciprocalAndMatchesTheEquationsAtEveryAngle) {
    for (double eta : {1.33, 1.5, 2.42}) {
        for (int k = 0; k <= 89; ++k) {
            const double thetaI = k * kPi / 180;
            const double thetaT = std::asin(std::sin(thetaI) / eta);
            const float outside = FresnelDielectric(float(std::cos(thetaI)), float(eta));
            const float inside = FresnelDielectric(float(std::cos(thetaT)), float(1 / eta));
            // Float rounding of cos(theta) grows toward grazing: measured 1.7e-5 at 89 degrees,
            // 2e-6 below 80. Tolerance 2e-6 / max(cos theta, 0.05): 4e-5 at grazing, where a
            // missing factor 1/2 or a reciprocal eta is off by 0.1 or more.
            const double tol = 2e-6 / std::max(std::cos(thetaI), 0.05);
            EXPECT_NEAR(outside, inside, tol) << "eta " << eta << " theta " << k;
            EXPECT_NEAR(outside, fresnelFromAngles(thetaI, 1.0, eta), tol) << "eta " << eta << " theta " << k;
            const double fromInside = fresnelFromAngles(thetaI, eta, 1.0);
            EXPECT_NEAR(FresnelDielectric(float(std::cos(thetaI)), float(1 / eta)), fromInside, tol)
                << "eta " << eta << " theta " << k << " inside";
        }
    }
}

// Snell's law and the plane of incidence: sin(thetaT) = sin(thetaI) / eta, wt in the plane of wi
// and n, on the other side; TIR refused. Reflection mirrors about n.
TEST(Optics, RefractObeysSnellsLaw) {
    const glm::vec3 n(0, 0, 1);
    for (double eta : {1.5, 1 / 1.5}) {
        for (int k = 0; k < 90; k += 7) {
            const double theta = k * kPi / 180;
            const glm::vec3 wi(float(std::sin(theta)), 0, float(std::cos(theta)));
            glm::vec3 wt;
            const double s = std::sin(theta) / eta;
            ASSERT_EQ(Refract(wi, n, float(eta), &wt), s < 1) << eta << " " << k;
            if (s >= 1) continue;
            EXPECT_NEAR(glm::length(wt), 1.0f, 1e-6f);
            EXPECT_NEAR(-wt.x, s, 1e-6) << eta << " " << k;  // tangential part reverses with -wi
            EXPECT_NEAR(wt.z, -std::sqrt(1 - s * s), 1e-6) << eta << " " << k;
            EXPECT_EQ(wt.y, 0.0f);
        }
    }
    const glm::vec3 r = Reflect(glm::normalize(glm::vec3(1, 2, 3)), n);
    EXPECT_NEAR(glm::distance(r, glm::normalize(glm::vec3(-1, -2, 3))), 0.0f, 1e-6f);
}

// The tone map is its documented formula (docs/runtime.md "Tone map"): exposure, the ACES fit of
// Narkowicz 2015, (x (2.51 x + 0.03)) / (x (2.43 x + 0.59) + 0.14) clamped to [0, 1], then the
// sRGB transfer function (IEC 61966-2-1: 12.92 x below 0.0031308, else 1.055 x^(1/2.4) - 0.055).
double acesThenSrgb(double x) {
    double y = (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
    y = std::min(1.0, std::max(0.0, y));
    return y <= 0.0031308 ? 12.92 * y : 1.055 * std::pow(y, 1 / 2.4) - 0.055;
}

TEST(Optics, ToneMapIsTheAcesFitThenSrgb) {
    for (int k = -40; k <= 40; ++k) {
        const double x = std::pow(2.0, k / 4.0);  // 2^-10 .. 2^10
        for (float exposure : {0.5f, 1.0f, 2.0f}) {
            const glm::vec3 t = toneMapAces(glm::vec3(float(x), float(x / 3), float(x * 3)), exposure);
            EXPECT_NEAR(t.r, acesThenSrgb(x * exposure), 2e-6) << x << " exposure " << exposure;
            EXPECT_NEAR(t.g, acesThenSrgb(x / 3 * exposure), 2e-6) << x;
            EXPECT_NEAR(t.b, acesThenSrgb(x * 3 * exposure), 2e-6) << x;
        }
    }
    EXPECT_EQ(toneMapAces(glm::vec3(0.0f)), glm::vec3(0.0f));
    const glm::vec3 white = toneMapAces(glm::vec3(1e6f));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(white[c], 1.0f, 1e-6f);
}

}  // namespace
}  // namespace shrefract
