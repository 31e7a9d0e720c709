// Lab 02: the renderer's math on a packet of lanes, written once for any lane type F: Float8
// (8 AVX2 lanes, simd8.h) or Float16 (16 AVX-512 lanes, simd16.h). Include one of those, not
// this file: each defines its lane type's operators and then includes this.
//
// Vec3xN<F> holds one Vec3 per lane as three registers: all x in one, all y in another, all z
// in a third (a structure of arrays, where Part A's Vec3 was one array of structures per
// register). The functions below read like the scalar code of vec3.h, ray.h, material.h and
// rng.h and do, lane by lane, its operations in its order, so every lane has its bits.
#pragma once

#include <cstdint>

#include <material.h>
#include <ray.h>
#include <rng.h>
#include <triangle.h>

template <class F>
using MaskOf = typename F::Mask;  // a true/false per lane of F
template <class F>
using IntOf = typename F::Int;  // an int per lane of F

// ---- Vec3 per lane -----------------------------------------------------------------------

template <class F>
struct Vec3xN {
    F x, y, z;  // component c of lane i is c.lane(i)

    Vec3xN() = default;
    Vec3xN(F x_, F y_, F z_) : x(x_), y(y_), z(z_) {}
    Vec3xN(Vec3 v) : x(v.x), y(v.y), z(v.z) {}  // NOLINT: the same Vec3 in every lane
    Vec3 lane(int i) const { return {x.lane(i), y.lane(i), z.lane(i)}; }
};

template <class F>
inline Vec3xN<F> operator+(const Vec3xN<F>& a, const Vec3xN<F>& b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class F>
inline Vec3xN<F> operator-(const Vec3xN<F>& a, const Vec3xN<F>& b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class F>
inline Vec3xN<F> operator-(const Vec3xN<F>& a) {
    return {-a.x, -a.y, -a.z};
}
template <class F>
inline Vec3xN<F> operator*(const Vec3xN<F>& a, const Vec3xN<F>& b) {
    return {a.x * b.x, a.y * b.y, a.z * b.z};
}
template <class F>
inline Vec3xN<F> operator*(const Vec3xN<F>& a, F s) {
    return {a.x * s, a.y * s, a.z * s};
}
template <class F>
inline Vec3xN<F>& operator+=(Vec3xN<F>& a, const Vec3xN<F>& b) {
    return a = a + b;
}
template <class F>
inline Vec3xN<F>& operator*=(Vec3xN<F>& a, const Vec3xN<F>& b) {
    return a = a * b;
}
template <class F>
inline Vec3xN<F> select(MaskOf<F> mask, const Vec3xN<F>& a, const Vec3xN<F>& b) {
    return {select(mask, a.x, b.x), select(mask, a.y, b.y), select(mask, a.z, b.z)};
}

// No horizontal work anywhere: a dot product of N pairs is 3 multiplies and 2 adds.
template <class F>
inline F dot(const Vec3xN<F>& a, const Vec3xN<F>& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class F>
inline F length_squared(const Vec3xN<F>& a) {
    return dot(a, a);
}
template <class F>
inline Vec3xN<F> normalize(const Vec3xN<F>& a) {
    return a * (F(1.0f) / sqrt(dot(a, a)));
}
template <class F>
inline Vec3xN<F> abs(const Vec3xN<F>& a) {
    return {abs(a.x), abs(a.y), abs(a.z)};
}
template <class F>
inline F max_component(const Vec3xN<F>& a) {
    return max(a.x, max(a.y, a.z));
}
template <class F>
inline Vec3xN<F> reflect(const Vec3xN<F>& d, const Vec3xN<F>& n) {
    return d - n * (F(2.0f) * dot(d, n));
}

// offset_ray_origin (ray.h), lane by lane: the lanes are float, and so is ray.h's
// kRelativeOffset in every build that includes this file (2^-20).
template <class F>
inline Vec3xN<F> offset_ray_origin(const Vec3xN<F>& p, const Vec3xN<F>& n, F distance_travelled,
                                   F extent) {
    static_assert(sizeof(kRelativeOffset) == sizeof(float), "SIMD lanes are float");
    const F scale = max_component(abs(p)) + distance_travelled + extent;
    return p + n * (scale * kRelativeOffset);
}

// orthonormal_basis (vec3.h), lane by lane.
template <class F>
inline void orthonormal_basis(const Vec3xN<F>& n, Vec3xN<F>& t, Vec3xN<F>& b) {
    const F sign = copysign(F(1.0f), n.z);
    const F a = F(-1.0f) / (sign + n.z);
    const F c = n.x * n.y * a;
    t = {F(1.0f) + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
}

// sin(2 pi u) and cos(2 pi u) for u in [0, 1): material.h's sincos_2pi with the same
// operations in the same order, so the same bits. The quadrant comes exactly from 4u, the
// rest from Cephes' single-precision polynomials on [-pi/4, pi/4].
template <class F>
inline void sincos_2pi(F u, F& s, F& c) {
    const F t = u * 4.0f;  // exact
    const F q = round_to_nearest(t);
    const F x = (t - q) * 1.57079632679489661923f;  // in [-pi/4, pi/4]
    const F z = x * x;
    const F sin_x =
        x + x * z * ((F(-1.9515295891e-4f) * z + 8.3321608736e-3f) * z - 1.6666654611e-1f);
    const F cos_x =
        F(1.0f) - z * 0.5f +
        z * z *
            ((F(2.443315711809948e-5f) * z - 1.388731625493765e-3f) * z + 4.166664568298827e-2f);
    // Quadrant k: sin = (sin x, cos x, -sin x, -cos x)[k], cos = (cos x, -sin x, -cos x, sin x)[k].
    const IntOf<F> k = to_int(q) & 3;
    const auto odd = (k & 1) == 1;
    const F s_abs = select(odd, cos_x, sin_x);
    const F c_abs = select(odd, sin_x, cos_x);
    s = select((k & 2) == 2, -s_abs, s_abs);
    c = select(((k ^ (k >> 1)) & 1) == 1, -c_abs, c_abs);
}

// sample_cosine_hemisphere (material.h), lane by lane.
template <class F>
inline Vec3xN<F> sample_cosine_hemisphere(const Vec3xN<F>& n, F u1, F u2) {
    const F r = sqrt(u1);
    F sin_phi, cos_phi;
    sincos_2pi(u2, sin_phi, cos_phi);
    const F x = r * cos_phi;
    const F y = r * sin_phi;
    const F z = sqrt(max(F(0.0f), F(1.0f) - u1));  // max_float's argument order
    Vec3xN<F> t, b;
    orthonormal_basis(n, t, b);
    return t * x + b * y + n * z;
}

// fresnel_dielectric (material.h), lane by lane.
template <class F>
inline F fresnel_dielectric(F cos_i, F eta, F& cos_t) {
    const F sin2_t = eta * eta * max(F(0.0f), F(1.0f) - cos_i * cos_i);
    const auto total = sin2_t >= 1.0f;
    cos_t = select(total, F(0.0f), sqrt(F(1.0f) - sin2_t));
    const F r_parallel = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    const F r_perpendicular = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    const F r = F(0.5f) * (r_parallel * r_parallel + r_perpendicular * r_perpendicular);
    return select(total, F(1.0f), r);
}

// refract (material.h), lane by lane.
template <class F>
inline Vec3xN<F> refract(const Vec3xN<F>& d, const Vec3xN<F>& n, F eta, F cos_t) {
    const F cos_i = -dot(d, n);
    return normalize(d * eta + n * (eta * cos_i - cos_t));
}

// ---- random numbers ----------------------------------------------------------------------

// SampleStream (rng.h) for the N paths of a packet: at() gives, per lane, exactly the float
// the scalar SampleStream of that lane's (seed, pixel, sample) gives.
template <class F>
class SampleStreamN {
    using U64 = typename F::U64;

public:
    // Samples first_sample .. first_sample + N - 1 of one pixel, one per lane.
    SampleStreamN(uint64_t seed, uint64_t pixel, uint64_t first_sample)
        : key_(mix64(U64::sequence(first_sample) ^ pixel_key(seed, pixel))) {}
    // Any samples of any pixels: lane i's key (the hash of its seed, pixel and sample, as
    // path_key gives it) split into its low and high 32-bit words.
    SampleStreamN(const uint32_t* key_low, const uint32_t* key_high)
        : key_(U64::load(key_low, key_high)) {}

    F at(uint32_t dimension) const {
        return unit_float(mix64(key_ + 0x9e3779b97f4a7c15ull * (dimension + 1ull)));
    }

    // SampleStream's hash of (seed, pixel), and of a sample of that pixel: its key.
    static uint64_t pixel_key(uint64_t seed, uint64_t pixel) {
        return ::mix64(::mix64(seed ^ 0x9e3779b97f4a7c15ull) ^ pixel);
    }
    static uint64_t path_key(uint64_t pixel_key, uint64_t sample) {
        return ::mix64(pixel_key ^ sample);
    }

private:
    U64 key_;  // hash of (seed, pixel, sample) per lane
};

// ---- the triangle test's rare case -------------------------------------------------------

// Where an edge function rounded to exactly zero (`on_edge`), recompute u, v, w of those
// lanes in double (triangle.h's edge_function_exact), so the sign is exact there too.
template <class F>
inline void redo_edges_exactly(MaskOf<F> on_edge, F ax, F ay, F bx, F by, F cx, F cy, F& u, F& v,
                               F& w) {
    constexpr int kN = F::kLanes;
    float uvw[3][kN];
    u.store(uvw[0]);
    v.store(uvw[1]);
    w.store(uvw[2]);
    for (unsigned bits = on_edge.bits(); bits != 0; bits &= bits - 1) {
        const int lane = __builtin_ctz(bits);
        const float lax = ax.lane(lane), lay = ay.lane(lane), lbx = bx.lane(lane);
        const float lby = by.lane(lane), lcx = cx.lane(lane), lcy = cy.lane(lane);
        uvw[0][lane] = static_cast<float>(edge_function_exact(lcx, lcy, lbx, lby));
        uvw[1][lane] = static_cast<float>(edge_function_exact(lax, lay, lcx, lcy));
        uvw[2][lane] = static_cast<float>(edge_function_exact(lbx, lby, lax, lay));
    }
    u = F::load(uvw[0]);
    v = F::load(uvw[1]);
    w = F::load(uvw[2]);
}

// The same for intersect_quad's four edge functions (v0v1, v1v2, v2v3, v3v0), as convex_quad.h
// computes them exactly.
template <class F>
inline void redo_quad_edges_exactly(MaskOf<F> on_edge, const F (&x)[4], const F (&y)[4],
                                    F (&e)[4]) {
    constexpr int kN = F::kLanes;
    float out[4][kN];
    for (int k = 0; k < 4; ++k) e[k].store(out[k]);
    for (unsigned bits = on_edge.bits(); bits != 0; bits &= bits - 1) {
        const int lane = __builtin_ctz(bits);
        for (int k = 0; k < 4; ++k) {
            const int q = (k + 1) % 4;  // edge k -> q, computed as edge_function(q, k)
            out[k][lane] = static_cast<float>(edge_function_exact(
                x[q].lane(lane), y[q].lane(lane), x[k].lane(lane), y[k].lane(lane)));
        }
    }
    for (int k = 0; k < 4; ++k) e[k] = F::load(out[k]);
}
