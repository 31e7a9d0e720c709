// Materials: cosine hemisphere sampling, exact Fresnel reflectance, Snell's law, and the
// orthonormal basis the sampling relies on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "material.h"
#include "rng.h"

namespace {

Vec3 random_unit(std::mt19937& gen) {
    std::normal_distribution<float> n(0.0f, 1.0f);
    for (;;) {
        const Vec3 v(n(gen), n(gen), n(gen));
        if (length(v) > 1e-3f) return normalize(v);
    }
}

}  // namespace

TEST(Material, OrthonormalBasis) {
    std::mt19937 gen(1);
    for (int i = 0; i < 10000; ++i) {
        Vec3 n = random_unit(gen);
        if (i == 0) n = {0, 0, 1};
        if (i == 1) n = {0, 0, -1};
        if (i == 2) n = {1, 0, 0};
        Vec3 t, b;
        orthonormal_basis(n, t, b);
        ASSERT_NEAR(length(t), 1.0f, 1e-5f);
        ASSERT_NEAR(length(b), 1.0f, 1e-5f);
        ASSERT_NEAR(dot(t, n), 0.0f, 1e-5f);
        ASSERT_NEAR(dot(b, n), 0.0f, 1e-5f);
        ASSERT_NEAR(dot(t, b), 0.0f, 1e-5f);
    }
}

TEST(Material, CosineHemisphereUnitAndInHemisphere) {
    std::mt19937 gen(2);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 0; i < 20000; ++i) {
        const Vec3 n = random_unit(gen);
        const Vec3 d = sample_cosine_hemisphere(n, u(gen), u(gen));
        ASSERT_NEAR(length(d), 1.0f, 1e-5f);
        ASSERT_GE(dot(d, n), -1e-6f);
    }
    // The extreme inputs of a [0, 1) generator.
    const Vec3 n(0, 1, 0);
    for (float u1 : {0.0f, 1.0f - 1.0f / 16777216.0f})
        for (float u2 : {0.0f, 0.5f, 1.0f - 1.0f / 16777216.0f}) {
            const Vec3 d = sample_cosine_hemisphere(n, u1, u2);
            EXPECT_NEAR(length(d), 1.0f, 1e-5f);
            EXPECT_GE(d.y, 0.0f);
        }
}

TEST(Material, CosineHemisphereMoments) {
    // For pdf cos/pi: E[cos] = 2/3, E[cos^2] = 1/2, and the tangential mean is zero.
    const Vec3 n = normalize(Vec3(0.3f, -0.8f, 0.5f));
    const int count = 100000;
    double sum_cos = 0, sum_cos2 = 0;
    Vec3 t, b;
    orthonormal_basis(n, t, b);
    double sum_t = 0, sum_b = 0;
    for (int i = 0; i < count; ++i) {
        const SampleStream s(0, i, 0);
        const Vec3 d = sample_cosine_hemisphere(n, s.at(0), s.at(1));
        const double c = dot(d, n);
        sum_cos += c;
        sum_cos2 += c * c;
        sum_t += dot(d, t);
        sum_b += dot(d, b);
    }
    EXPECT_NEAR(sum_cos / count, 2.0 / 3.0, 0.005);  // sd of the mean ~0.0007
    EXPECT_NEAR(sum_cos2 / count, 0.5, 0.005);
    EXPECT_NEAR(sum_t / count, 0.0, 0.01);
    EXPECT_NEAR(sum_b / count, 0.0, 0.01);
}

TEST(Material, CosineHemisphereIsCosineDistributed) {
    // P(cos theta <= c) = c^2 for the cosine-weighted hemisphere: check at 10 quantiles.
    const Vec3 n(0, 0, 1);
    const int count = 100000;
    std::vector<int> bins(10, 0);
    for (int i = 0; i < count; ++i) {
        const SampleStream s(1, i, 0);
        const float c = dot(sample_cosine_hemisphere(n, s.at(0), s.at(1)), n);
        const int k = std::min(9, static_cast<int>(c * c * 10));  // c^2 is uniform
        ++bins[k];
    }
    double chi2 = 0;
    for (int k : bins) chi2 += (k - count / 10.0) * (k - count / 10.0) / (count / 10.0);
    EXPECT_LT(chi2, 40);  // 9 dof: mean 9, sd 4.2
}

TEST(Material, FresnelNormalIncidence) {
    for (float n : {1.0f, 1.33f, 1.5f, 2.4f}) {
        float cos_t = -1;
        const float expected = ((n - 1) / (n + 1)) * ((n - 1) / (n + 1));
        EXPECT_NEAR(fresnel_dielectric(1.0f, 1.0f / n, cos_t), expected, 1e-6f) << n;
        EXPECT_NEAR(cos_t, 1.0f, 1e-6f);
        EXPECT_NEAR(fresnel_dielectric(1.0f, n, cos_t), expected, 1e-6f) << "from inside " << n;
    }
    float cos_t;
    EXPECT_NEAR(fresnel_dielectric(1.0f, 1.0f / 1.5f, cos_t), 0.04f, 1e-6f);
}

TEST(Material, FresnelTotalInternalReflection) {
    // From glass (n = 1.5) into air: critical angle asin(1/1.5) = 41.8 degrees.
    const float eta = 1.5f;
    const float critical = std::asin(1.0f / eta);
    for (float angle : {critical + 0.01f, 1.0f, 1.4f, 1.5707f}) {
        float cos_t = -1;
        EXPECT_EQ(fresnel_dielectric(std::cos(angle), eta, cos_t), 1.0f) << angle;
        EXPECT_EQ(cos_t, 0.0f);
    }
    float cos_t;
    EXPECT_LT(fresnel_dielectric(std::cos(critical - 0.01f), eta, cos_t), 1.0f);
    EXPECT_GT(cos_t, 0.0f);
}

TEST(Material, FresnelInUnitIntervalAndMonotoneFromAir) {
    float previous = 0;
    for (int i = 0; i <= 1000; ++i) {
        const float cos_i = 1.0f - i / 1000.0f;  // from normal to grazing
        for (float eta : {1.0f / 1.5f, 1.5f, 1.0f / 2.4f, 1.0f / 1.0001f}) {
            float cos_t;
            const float r = fresnel_dielectric(cos_i, eta, cos_t);
            ASSERT_GE(r, 0.0f) << cos_i << " " << eta;
            ASSERT_LE(r, 1.0f) << cos_i << " " << eta;
            ASSERT_FALSE(std::isnan(cos_t));
        }
        float cos_t;
        const float r = fresnel_dielectric(cos_i, 1.0f / 1.5f, cos_t);
        if (cos_i > 0.2f) {  // past Brewster's angle the unpolarised curve rises monotonically
            ASSERT_GE(r, previous - 1e-6f) << cos_i;
        }
        previous = r;
    }
    float cos_t;
    EXPECT_NEAR(fresnel_dielectric(1e-6f, 1.0f / 1.5f, cos_t), 1.0f, 1e-4f);  // grazing
}

TEST(Material, FresnelMatchesKnownValue) {
    // Air to glass (1.5) at 45 degrees: Rs = 0.0920, Rp = 0.00847, mean 0.0502.
    float cos_t;
    const float r = fresnel_dielectric(std::cos(45.0f * kPi / 180.0f), 1.0f / 1.5f, cos_t);
    EXPECT_NEAR(r, 0.05023f, 2e-4f);
    EXPECT_NEAR(cos_t, std::sqrt(1.0f - 0.5f / 2.25f), 1e-6f);
}

TEST(Material, RefractObeysSnell) {
    std::mt19937 gen(3);
    for (int i = 0; i < 10000; ++i) {
        const Vec3 n = random_unit(gen);
        Vec3 d = random_unit(gen);
        if (dot(d, n) > 0) d = -d;  // incoming, against the normal
        if (dot(d, n) > -1e-3f) continue;
        const float eta = (i % 2) ? 1.0f / 1.5f : 1.5f;
        const float cos_i = -dot(d, n);
        float cos_t;
        const float r = fresnel_dielectric(cos_i, eta, cos_t);
        if (r == 1.0f) continue;  // total internal reflection
        const Vec3 t = refract(d, n, eta, cos_t);
        ASSERT_NEAR(length(t), 1.0f, 1e-5f);
        ASSERT_NEAR(-dot(t, n), cos_t, 2e-4f);  // goes through, at the transmitted angle
        const float sin_i = length(cross(d, n)), sin_t = length(cross(t, n));
        ASSERT_NEAR(sin_t, eta * sin_i, 2e-4f) << "Snell: n1 sin i = n2 sin t";
        ASSERT_NEAR(dot(cross(d, n), t), 0.0f, 1e-4f) << "t lies in the plane of d and n";
        ASSERT_GE(dot(cross(d, n), cross(t, n)), 0.0f) << "same side of the normal";
    }
    // Normal incidence passes straight through; eta = 1 leaves the direction unchanged.
    float cos_t;
    fresnel_dielectric(1.0f, 1.0f / 1.5f, cos_t);
    const Vec3 straight = refract({0, 0, -1}, {0, 0, 1}, 1.0f / 1.5f, cos_t);
    EXPECT_NEAR(straight.z, -1.0f, 1e-6f);
    const Vec3 d = normalize(Vec3(1, 0, -1));
    fresnel_dielectric(-d.z, 1.0f, cos_t);
    const Vec3 same = refract(d, {0, 0, 1}, 1.0f, cos_t);
    EXPECT_NEAR(same.x, d.x, 1e-6f);
    EXPECT_NEAR(same.z, d.z, 1e-6f);
}

TEST(Material, ReflectMirrorsAboutTheNormal) {
    const Vec3 r = reflect(normalize(Vec3(1, -1, 0)), {0, 1, 0});
    EXPECT_NEAR(r.x, std::sqrt(0.5f), 1e-6f);
    EXPECT_NEAR(r.y, std::sqrt(0.5f), 1e-6f);
    EXPECT_NEAR(r.z, 0.0f, 1e-6f);
}
