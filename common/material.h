// The three materials and how each turns an incoming direction into an outgoing one.
#pragma once

#include <cmath>

#include "vec3.h"

enum class MaterialType : int { Diffuse = 0, Mirror = 1, Glass = 2 };

struct Material {
    MaterialType type;  // which BSDF
    Vec3 albedo;        // diffuse reflectance or mirror tint (unused by glass)
    float ior;          // index of refraction inside glass (unused otherwise)
};

constexpr float kPi = 3.14159265358979323846f;

// Cosine-weighted direction about unit normal n from two uniform numbers (Malley's method).
// Its pdf cos/pi cancels the Lambertian BRDF's cos/pi, so throughput simply gains the albedo.
RT_HD inline Vec3 sample_cosine_hemisphere(Vec3 n, float u1, float u2) {
    const float r = sqrtf(u1);
    const float phi = 2.0f * kPi * u2;
    const float x = r * cosf(phi);
    const float y = r * sinf(phi);
    const float z = sqrtf(max_float(0.0f, 1.0f - u1));
    Vec3 t, b;
    orthonormal_basis(n, t, b);
    return t * x + b * y + n * z;
}

// Unpolarised Fresnel reflectance of a smooth dielectric (exact, not Schlick's fit).
// cos_i: cosine of the incident angle (> 0); eta = n_incident / n_transmitted.
// Returns 1 for total internal reflection and stores the transmitted cosine in cos_t.
RT_HD inline float fresnel_dielectric(float cos_i, float eta, float& cos_t) {
    const float sin2_t = eta * eta * max_float(0.0f, 1.0f - cos_i * cos_i);
    if (sin2_t >= 1.0f) {
        cos_t = 0.0f;
        return 1.0f;
    }
    cos_t = sqrtf(1.0f - sin2_t);
    const float r_parallel = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    const float r_perpendicular = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5f * (r_parallel * r_parallel + r_perpendicular * r_perpendicular);
}

// Refracted direction of unit d through a surface with unit normal n facing d's side,
// given eta and the transmitted cosine from fresnel_dielectric.
RT_HD inline Vec3 refract(Vec3 d, Vec3 n, float eta, float cos_t) {
    const float cos_i = -dot(d, n);
    return normalize(d * eta + n * (eta * cos_i - cos_t));
}
