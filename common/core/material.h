// The material kinds and how each turns an incoming direction into an outgoing one.
#pragma once

#include <cmath>

#include <kinds.h>
#include <ray.h>
#include <real.h>
#include <rng.h>
#include <vec3.h>

// A material's kind: its position in AllMaterials (material_type<Glass> is 2).
enum class MaterialType : int {};

struct Material {
    MaterialType type;  // which BSDF: material_type<K> for a kind K of AllMaterials
    Vec3 albedo;        // diffuse reflectance or mirror tint (unused by glass)
    real ior;           // index of refraction inside glass (unused otherwise)
};

// A number a material kind reads from its entry in a scene file (host/scene_loader.cpp): its
// key, the field of Material it sets and the closed range it must lie in. A null key: none.
using MaterialField = real Material::*;
struct MaterialNumber {
    const char* key = nullptr;
    MaterialField field = nullptr;
    double lo = 0, hi = 0;
    const char* what = nullptr;  // what the error calls it: "an index of refraction"
};

// The material kinds, declared here once: AllMaterials lists them, a material's type is its
// kind's position in the list, and every set a renderer is compiled for names its kinds
// (material_set.h). A kind has
//   kName          its "type" in a scene file and what the scene report calls one;
//   kReportKey     its --json key;
//   kAlbedo        whether its entry has an "albedo" (in [0, 1] per channel);
//   kNumber        the one number more its entry has, if any (MaterialNumber);
// and, but for Diffuse (the kind that samples the light: path_steps.h's bounce step), a hook
//   scatter(K{}, material, SpecularHit, rng, bounce, throughput, next)
// that continues the path: the next ray and the throughput's weight (below).
struct Diffuse {  // Lambertian: albedo / pi
    static constexpr const char* kName = "diffuse";
    static constexpr const char* kReportKey = "diffuse";
    static constexpr bool kAlbedo = true;
    static constexpr MaterialNumber kNumber{};
};
struct Mirror {  // perfect specular reflection, tinted by the albedo
    static constexpr const char* kName = "mirror";
    static constexpr const char* kReportKey = "mirrors";
    static constexpr bool kAlbedo = true;
    static constexpr MaterialNumber kNumber{};
};
struct Glass {  // smooth dielectric: Fresnel reflection or refraction by the ior
    static constexpr const char* kName = "glass";
    static constexpr const char* kReportKey = "glass";
    static constexpr bool kAlbedo = false;
    static constexpr MaterialNumber kNumber{"ior", &Material::ior, 1.0, 5.0,
                                            "an index of refraction"};
};

using AllMaterials = Kinds<Diffuse, Mirror, Glass>;

template <class K>
struct MaterialTypeOf {
    static_assert(has_kind<AllMaterials, K>, "a material kind is one of AllMaterials");
    static constexpr MaterialType value = static_cast<MaterialType>(kind_index<AllMaterials, K>);
};
template <class K>
constexpr MaterialType material_type = MaterialTypeOf<K>::value;

constexpr real kPi = real(3.14159265358979323846);

// sin(2 pi u) and cos(2 pi u) for u in [0, 1), without a libm call on the hot path. The
// quadrant comes exactly from 4u, the rest from Cephes' single-precision polynomials on
// [-pi/4, pi/4] (about 1 ulp). Lab 02's sincos_2pi8 (simd8.h) is this, lane by lane, with the
// same operations in the same order, so both give the same bits. The double build computes
// in double but keeps these single-precision polynomials (about 1e-7): the random directions
// then differ from the float build's by rounding only.
RT_HD inline void sincos_2pi(real u, real& s, real& c) {
    const real t = u * real(4);  // exact
    const real q = rint_real(t);
    const real x = (t - q) * real(1.57079632679489661923);  // in [-pi/4, pi/4]
    const real z = x * x;
    const real sin_x =
        x + x * z * ((-1.9515295891e-4f * z + 8.3321608736e-3f) * z - 1.6666654611e-1f);
    const real cos_x =
        1.0f - z * 0.5f +
        z * z * ((2.443315711809948e-5f * z - 1.388731625493765e-3f) * z + 4.166664568298827e-2f);
    // Quadrant k: sin = (sin x, cos x, -sin x, -cos x)[k], cos = (cos x, -sin x, -cos x, sin x)[k].
    const int k = static_cast<int>(q) & 3;
    const real s_abs = (k & 1) ? cos_x : sin_x;
    const real c_abs = (k & 1) ? sin_x : cos_x;
    s = (k & 2) ? -s_abs : s_abs;
    c = ((k ^ (k >> 1)) & 1) ? -c_abs : c_abs;
}

// Cosine-weighted direction about unit normal n from two uniform numbers (Malley's method).
// Its pdf cos/pi cancels the Lambertian BRDF's cos/pi, so throughput simply gains the albedo.
RT_HD inline Vec3 sample_cosine_hemisphere(Vec3 n, real u1, real u2) {
    const real r = sqrt_real(u1);
    real sin_phi, cos_phi;
    sincos_2pi(u2, sin_phi, cos_phi);
    const real x = r * cos_phi;
    const real y = r * sin_phi;
    const real z = sqrt_real(max_float(0.0f, 1.0f - u1));
    Vec3 t, b;
    orthonormal_basis(n, t, b);
    const Vec3 d = t * x + b * y + n * z;
    // The single-precision polynomials leave |d| off 1 by up to ~1e-7. Float's ray offsets
    // (2^-20, ray.h) cover that; double's (2^-49) do not, and the sphere test, which assumes
    // a unit direction, then put hit points below the surface by ~1e-7 of the distance.
    if constexpr (sizeof(real) > sizeof(float)) return normalize(d);
    return d;
}

// Unpolarised Fresnel reflectance of a smooth dielectric (exact, not Schlick's fit).
// cos_i: cosine of the incident angle (> 0); eta = n_incident / n_transmitted.
// Returns 1 for total internal reflection and stores the transmitted cosine in cos_t.
RT_HD inline real fresnel_dielectric(real cos_i, real eta, real& cos_t) {
    const real sin2_t = eta * eta * max_float(0.0f, 1.0f - cos_i * cos_i);
    if (sin2_t >= 1.0f) {
        cos_t = 0.0f;
        return 1.0f;
    }
    cos_t = sqrt_real(1.0f - sin2_t);
    const real r_parallel = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    const real r_perpendicular = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5f * (r_parallel * r_parallel + r_perpendicular * r_perpendicular);
}

// Refracted direction of unit d through a surface with unit normal n facing d's side,
// given eta and the transmitted cosine from fresnel_dielectric.
RT_HD inline Vec3 refract(Vec3 d, Vec3 n, real eta, real cos_t) {
    const real cos_i = -dot(d, n);
    return normalize(d * eta + n * (eta * cos_i - cos_t));
}

// What a kind's scatter hook reads of a specular hit (path_steps.h's bounce step fills it in).
struct SpecularHit {
    Vec3 incoming;  // the ray's unit direction
    Vec3 facing;  // the unit geometric normal on the ray's side
    bool entering;  // whether the ray meets the outward (front) side
    Vec3 above;  // the next ray's origin on the ray's side (offset_ray_origin, ray.h)
    Vec3 off_edges;  // the step off the primitive's edges every next origin adds
    Vec3 position;  // the hit point, its distance along the ray and the primitive's extent:
    real t;  // what an origin on the other side is offset by
    real extent;
};

// The mirror: the reflected direction, renormalised (unnormalised, its length drifts by ~1e-7
// a bounce; the sphere test assumes a unit direction, and after ~10 bounces its hits overshoot
// the ray offset: the paths escaped a closed mirror sphere).
template <class Rng>
RT_HD RT_FORCE_INLINE void scatter(Mirror, const Material& material, const SpecularHit& hit,
                                   const Rng&, int, Vec3& throughput, Ray& next) {
    throughput *= material.albedo;
    next = {hit.above + hit.off_edges, normalize(reflect(hit.incoming, hit.facing))};
}

// Glass: reflect or refract, chosen with the Fresnel reflectance. refract() normalises.
template <class Rng>
RT_HD RT_FORCE_INLINE void scatter(Glass, const Material& material, const SpecularHit& hit,
                                   const Rng& rng, int bounce, Vec3&, Ray& next) {
    const real eta = hit.entering ? real(1) / material.ior : material.ior;
    real cos_t;
    const real reflectance = fresnel_dielectric(-dot(hit.incoming, hit.facing), eta, cos_t);
    if (rng.at(bounce_dimension(bounce, 0)) < reflectance) {
        next = {hit.above + hit.off_edges, normalize(reflect(hit.incoming, hit.facing))};
    } else {
        const Vec3 below = offset_ray_origin(hit.position, -hit.facing, hit.t, hit.extent);
        next = {below + hit.off_edges, refract(hit.incoming, hit.facing, eta, cos_t)};
    }
}

// The scatter hook of the material's kind among Kinds<K, Rest...>: an if-chain
// over the kinds, the last taken without a test.
template <class Rng, class K, class... Rest>
RT_HD RT_FORCE_INLINE void scatter_of(const Material& material, const SpecularHit& hit,
                                      const Rng& rng, int bounce, Vec3& throughput, Ray& next,
                                      Kinds<K, Rest...>) {
    if constexpr (sizeof...(Rest) > 0) {
        if (material.type == material_type<K>)
            scatter(K{}, material, hit, rng, bounce, throughput, next);
        else scatter_of(material, hit, rng, bounce, throughput, next, Kinds<Rest...>{});
    } else {
        scatter(K{}, material, hit, rng, bounce, throughput, next);
    }
}
