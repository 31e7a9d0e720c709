// Lab 02 Part B: 8-lane values for AVX2 and the renderer's math on them.
//
// Float8 holds 8 floats (one __m256), Mask8 a true/false per lane, Int8 8 ints, Vec3x8 eight
// Vec3s as three registers: all x in one, all y in another, all z in a third (a structure of
// arrays, where Part A's Vec3 was one array of structures per register). Every operator is
// one named intrinsic, so what the hardware does stays visible, and the code that uses them
// reads like the scalar code of vec3.h, ray.h and material.h.
//
// Per lane, each function does exactly the scalar function's operations in the scalar
// function's order, and never a fused multiply-add (the intrinsics below are separate
// multiplies and adds; the build's -ffp-contract=off keeps the compiler from fusing them).
// So a lane computes the same bits as the scalar code, sin and cos included (sincos_2pi8 is
// material.h's sincos_2pi, lane by lane), and lab 02's image is lab 01's, bit for bit.
#pragma once

#if !defined(__AVX2__)
#error "simd8.h needs AVX2: compile this file with -mavx2 -mfma (labs/02-simd/lab.mk does)"
#endif

#include <immintrin.h>

#include <cstdint>

#include <material.h>
#include <ray.h>
#include <rng.h>
#include <triangle.h>

constexpr int kLanes = 8;  // floats in one AVX2 register

// ---- masks -----------------------------------------------------------------------------

// A true/false per lane: all ones or all zeros, as the comparisons produce.
struct Mask8 {
    __m256 m;

    static Mask8 all() { return {_mm256_castsi256_ps(_mm256_set1_epi32(-1))}; }
    static Mask8 none() { return {_mm256_setzero_ps()}; }
    // Lanes 0..count-1 true (count 0..8).
    static Mask8 first(int count) {
        const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        return {_mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(count), lane))};
    }
    int bits() const { return _mm256_movemask_ps(m); }  // bit i: lane i
};

inline Mask8 operator&(Mask8 a, Mask8 b) { return {_mm256_and_ps(a.m, b.m)}; }
inline Mask8 operator|(Mask8 a, Mask8 b) { return {_mm256_or_ps(a.m, b.m)}; }
inline Mask8 operator~(Mask8 a) { return {_mm256_xor_ps(a.m, Mask8::all().m)}; }
inline Mask8 and_not(Mask8 a, Mask8 b) { return {_mm256_andnot_ps(b.m, a.m)}; }  // a & ~b
inline Mask8& operator&=(Mask8& a, Mask8 b) { return a = a & b; }
inline Mask8& operator|=(Mask8& a, Mask8 b) { return a = a | b; }
inline bool any(Mask8 a) { return a.bits() != 0; }
inline bool none(Mask8 a) { return a.bits() == 0; }

// ---- floats ----------------------------------------------------------------------------

// 8 floats. A plain float converts to all 8 lanes.
struct Float8 {
    __m256 v;

    Float8() = default;
    Float8(__m256 v_) : v(v_) {}                     // NOLINT: implicit by design
    Float8(float s) : v(_mm256_set1_ps(s)) {}        // NOLINT: broadcast
    static Float8 load(const float* p) { return {_mm256_loadu_ps(p)}; }
    void store(float* p) const { _mm256_storeu_ps(p, v); }
    float lane(int i) const {
        return _mm256_cvtss_f32(_mm256_permutevar8x32_ps(v, _mm256_set1_epi32(i)));
    }
};

inline Float8 operator+(Float8 a, Float8 b) { return _mm256_add_ps(a.v, b.v); }
inline Float8 operator-(Float8 a, Float8 b) { return _mm256_sub_ps(a.v, b.v); }
inline Float8 operator*(Float8 a, Float8 b) { return _mm256_mul_ps(a.v, b.v); }
inline Float8 operator/(Float8 a, Float8 b) { return _mm256_div_ps(a.v, b.v); }
inline Float8 operator-(Float8 a) { return _mm256_xor_ps(a.v, _mm256_set1_ps(-0.0f)); }  // exact
inline Float8& operator+=(Float8& a, Float8 b) { return a = a + b; }
inline Float8& operator*=(Float8& a, Float8 b) { return a = a * b; }

// Comparisons: the _OQ predicates are false when a lane holds NaN, like scalar <, >, ==.
inline Mask8 operator<(Float8 a, Float8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_LT_OQ)}; }
inline Mask8 operator<=(Float8 a, Float8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_LE_OQ)}; }
inline Mask8 operator>(Float8 a, Float8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_GT_OQ)}; }
inline Mask8 operator>=(Float8 a, Float8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_GE_OQ)}; }
inline Mask8 operator==(Float8 a, Float8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_EQ_OQ)}; }
inline Mask8 operator!=(Float8 a, Float8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_NEQ_OQ)}; }

// mask ? a : b in each lane: how a branch of the scalar code becomes straight-line code.
inline Float8 select(Mask8 mask, Float8 a, Float8 b) { return _mm256_blendv_ps(b.v, a.v, mask.m); }

inline Float8 sqrt(Float8 a) { return _mm256_sqrt_ps(a.v); }  // correctly rounded, as sqrtf
inline Float8 abs(Float8 a) { return _mm256_andnot_ps(_mm256_set1_ps(-0.0f), a.v); }
// a < b ? a : b and a > b ? a : b: exactly min_float(a, b) / max_float(a, b), argument order,
// NaN and signed zeros included (MINPS/MAXPS return the second operand unless the comparison
// holds).
inline Float8 min(Float8 a, Float8 b) { return _mm256_min_ps(a.v, b.v); }
inline Float8 max(Float8 a, Float8 b) { return _mm256_max_ps(a.v, b.v); }
inline Float8 copysign(Float8 magnitude, Float8 sign) {
    const __m256 sign_bit = _mm256_set1_ps(-0.0f);
    return _mm256_or_ps(_mm256_andnot_ps(sign_bit, magnitude.v), _mm256_and_ps(sign_bit, sign.v));
}

// ---- ints (indices) --------------------------------------------------------------------

struct Int8 {
    __m256i v;

    Int8() = default;
    Int8(__m256i v_) : v(v_) {}                   // NOLINT: implicit by design
    explicit Int8(int s) : v(_mm256_set1_epi32(s)) {}  // broadcast
    int lane(int i) const {
        return _mm256_cvtsi256_si32(_mm256_permutevar8x32_epi32(v, _mm256_set1_epi32(i)));
    }
};

inline Mask8 operator==(Int8 a, Int8 b) {
    return {_mm256_castsi256_ps(_mm256_cmpeq_epi32(a.v, b.v))};
}
inline Mask8 operator==(Int8 a, int b) { return a == Int8(b); }
inline Int8 operator+(Int8 a, int b) { return _mm256_add_epi32(a.v, _mm256_set1_epi32(b)); }
inline Int8 select(Mask8 mask, Int8 a, Int8 b) {
    return _mm256_castps_si256(
        _mm256_blendv_ps(_mm256_castsi256_ps(b.v), _mm256_castsi256_ps(a.v), mask.m));
}
// ---- 8 Vec3s as three registers ----------------------------------------------------------

struct Vec3x8 {
    Float8 x, y, z;  // component c of lane i is c.lane(i)

    Vec3x8() = default;
    Vec3x8(Float8 x_, Float8 y_, Float8 z_) : x(x_), y(y_), z(z_) {}
    Vec3x8(Vec3 v) : x(v.x), y(v.y), z(v.z) {}  // NOLINT: the same Vec3 in every lane
    Vec3 lane(int i) const { return {x.lane(i), y.lane(i), z.lane(i)}; }
};

inline Vec3x8 operator+(const Vec3x8& a, const Vec3x8& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3x8 operator-(const Vec3x8& a, const Vec3x8& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3x8 operator-(const Vec3x8& a) { return {-a.x, -a.y, -a.z}; }
inline Vec3x8 operator*(const Vec3x8& a, const Vec3x8& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
inline Vec3x8 operator*(const Vec3x8& a, Float8 s) { return {a.x * s, a.y * s, a.z * s}; }
inline Vec3x8& operator+=(Vec3x8& a, const Vec3x8& b) { return a = a + b; }
inline Vec3x8& operator*=(Vec3x8& a, const Vec3x8& b) { return a = a * b; }
inline Vec3x8 select(Mask8 mask, const Vec3x8& a, const Vec3x8& b) {
    return {select(mask, a.x, b.x), select(mask, a.y, b.y), select(mask, a.z, b.z)};
}

// No horizontal work anywhere: a dot product of 8 pairs is 3 multiplies and 2 adds.
inline Float8 dot(const Vec3x8& a, const Vec3x8& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Float8 length_squared(const Vec3x8& a) { return dot(a, a); }
inline Vec3x8 normalize(const Vec3x8& a) { return a * (Float8(1.0f) / sqrt(dot(a, a))); }
inline Vec3x8 abs(const Vec3x8& a) { return {abs(a.x), abs(a.y), abs(a.z)}; }
inline Float8 max_component(const Vec3x8& a) { return max(a.x, max(a.y, a.z)); }
inline Vec3x8 reflect(const Vec3x8& d, const Vec3x8& n) { return d - n * (2.0f * dot(d, n)); }

// offset_ray_origin (ray.h), lane by lane.
inline Vec3x8 offset_ray_origin(const Vec3x8& p, const Vec3x8& n, Float8 distance_travelled,
                                Float8 extent) {
    constexpr float kRelativeOffset = 1.0f / (1 << 20);
    const Float8 scale = max_component(abs(p)) + distance_travelled + extent;
    return p + n * (scale * kRelativeOffset);
}

// orthonormal_basis (vec3.h), lane by lane.
inline void orthonormal_basis(const Vec3x8& n, Vec3x8& t, Vec3x8& b) {
    const Float8 sign = copysign(1.0f, n.z);
    const Float8 a = Float8(-1.0f) / (sign + n.z);
    const Float8 c = n.x * n.y * a;
    t = {Float8(1.0f) + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
}

// sin(2 pi u) and cos(2 pi u) for u in [0, 1). The quadrant comes exactly from 4u, the rest
// from Cephes' single-precision polynomials on [-pi/4, pi/4] (about 1 ulp): sincos_2pi
// (material.h) with the same operations in the same order, so the same bits.
inline void sincos_2pi8(Float8 u, Float8& s, Float8& c) {
    const Float8 t = u * 4.0f;                                   // exact
    const Float8 q = _mm256_round_ps(t.v, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
    const Float8 x = (t - q) * 1.57079632679489661923f;          // in [-pi/4, pi/4]
    const Float8 z = x * x;
    const Float8 sin_x =
        x + x * z * ((Float8(-1.9515295891e-4f) * z + 8.3321608736e-3f) * z - 1.6666654611e-1f);
    const Float8 cos_x = Float8(1.0f) - z * 0.5f +
                         z * z * ((Float8(2.443315711809948e-5f) * z - 1.388731625493765e-3f) * z +
                                  4.166664568298827e-2f);
    // Quadrant k = q mod 4: sin = (sin x, cos x, -sin x, -cos x)[k], cos = (cos, -sin, -cos, sin)[k].
    const __m256i k = _mm256_and_si256(_mm256_cvtps_epi32(q.v), _mm256_set1_epi32(3));
    const Mask8 odd{_mm256_castsi256_ps(_mm256_cmpeq_epi32(
        _mm256_and_si256(k, _mm256_set1_epi32(1)), _mm256_set1_epi32(1)))};
    const Mask8 sin_negative{_mm256_castsi256_ps(_mm256_slli_epi32(_mm256_srli_epi32(k, 1), 31))};
    const Mask8 cos_negative{_mm256_castsi256_ps(
        _mm256_slli_epi32(_mm256_xor_si256(k, _mm256_srli_epi32(k, 1)), 31))};
    const Float8 s_abs = select(odd, cos_x, sin_x);
    const Float8 c_abs = select(odd, sin_x, cos_x);
    s = _mm256_xor_ps(s_abs.v, _mm256_and_ps(sin_negative.m, _mm256_set1_ps(-0.0f)));
    c = _mm256_xor_ps(c_abs.v, _mm256_and_ps(cos_negative.m, _mm256_set1_ps(-0.0f)));
}

// sample_cosine_hemisphere (material.h), lane by lane; sin/cos by sincos_2pi8.
inline Vec3x8 sample_cosine_hemisphere(const Vec3x8& n, Float8 u1, Float8 u2) {
    const Float8 r = sqrt(u1);
    Float8 sin_phi, cos_phi;
    sincos_2pi8(u2, sin_phi, cos_phi);
    const Float8 x = r * cos_phi;
    const Float8 y = r * sin_phi;
    const Float8 z = sqrt(max(Float8(0.0f), Float8(1.0f) - u1));  // max_float's argument order
    Vec3x8 t, b;
    orthonormal_basis(n, t, b);
    return t * x + b * y + n * z;
}

// fresnel_dielectric (material.h), lane by lane.
inline Float8 fresnel_dielectric(Float8 cos_i, Float8 eta, Float8& cos_t) {
    const Float8 sin2_t = eta * eta * max(Float8(0.0f), Float8(1.0f) - cos_i * cos_i);
    const Mask8 total = sin2_t >= 1.0f;
    cos_t = select(total, Float8(0.0f), sqrt(Float8(1.0f) - sin2_t));
    const Float8 r_parallel = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    const Float8 r_perpendicular = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    const Float8 r = Float8(0.5f) * (r_parallel * r_parallel + r_perpendicular * r_perpendicular);
    return select(total, Float8(1.0f), r);
}

// refract (material.h), lane by lane.
inline Vec3x8 refract(const Vec3x8& d, const Vec3x8& n, Float8 eta, Float8 cos_t) {
    const Float8 cos_i = -dot(d, n);
    return normalize(d * eta + n * (eta * cos_i - cos_t));
}

// ---- random numbers ----------------------------------------------------------------------

// 8 unsigned 64-bit integers, lanes 0-3 in lo and 4-7 in hi.
struct U64x8 {
    __m256i lo, hi;
};

// x * c mod 2^64 per 64-bit lane. AVX2 multiplies only 32 x 32 -> 64 bits, so the product is
// lo(x)lo(c) + (hi(x)lo(c) + lo(x)hi(c)) << 32: three multiplies where the scalar code has one.
inline __m256i mul64(__m256i x, uint64_t c) {
    const __m256i c_lo = _mm256_set1_epi64x(static_cast<long long>(c & 0xffffffffu));
    const __m256i c_hi = _mm256_set1_epi64x(static_cast<long long>(c >> 32));
    const __m256i low = _mm256_mul_epu32(x, c_lo);
    const __m256i cross = _mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64(x, 32), c_lo),
                                           _mm256_mul_epu32(x, c_hi));
    return _mm256_add_epi64(low, _mm256_slli_epi64(cross, 32));
}

// mix64 (rng.h) on 4 lanes.
inline __m256i mix64(__m256i z) {
    z = mul64(_mm256_xor_si256(z, _mm256_srli_epi64(z, 30)), 0xbf58476d1ce4e5b9ull);
    z = mul64(_mm256_xor_si256(z, _mm256_srli_epi64(z, 27)), 0x94d049bb133111ebull);
    return _mm256_xor_si256(z, _mm256_srli_epi64(z, 31));
}

// SampleStream (rng.h) for 8 consecutive samples of one pixel: lane i is sample first + i,
// and at() gives, per lane, exactly the float the scalar SampleStream gives.
class SampleStream8 {
public:
    SampleStream8(uint64_t seed, uint64_t pixel, uint64_t first_sample) {
        const uint64_t pixel_key = ::mix64(::mix64(seed ^ 0x9e3779b97f4a7c15ull) ^ pixel);
        const __m256i key = _mm256_set1_epi64x(static_cast<long long>(pixel_key));
        const __m256i s = _mm256_set1_epi64x(static_cast<long long>(first_sample));
        key_.lo = mix64(_mm256_xor_si256(key, _mm256_add_epi64(s, _mm256_setr_epi64x(0, 1, 2, 3))));
        key_.hi = mix64(_mm256_xor_si256(key, _mm256_add_epi64(s, _mm256_setr_epi64x(4, 5, 6, 7))));
    }

    Float8 at(uint32_t dimension) const {
        const __m256i step = _mm256_set1_epi64x(
            static_cast<long long>(0x9e3779b97f4a7c15ull * (dimension + 1ull)));
        // unit_float: the top 24 bits of each 64-bit word, as an int below 2^24, scaled.
        const __m256i lo = _mm256_srli_epi64(mix64(_mm256_add_epi64(key_.lo, step)), 40);
        const __m256i hi = _mm256_srli_epi64(mix64(_mm256_add_epi64(key_.hi, step)), 40);
        // 32-bit words (lo0, hi0, lo1, hi1, ...) -> (lo0, lo1, lo2, lo3, hi0, ..., hi3).
        const __m256i interleaved = _mm256_or_si256(lo, _mm256_slli_epi64(hi, 32));
        const __m256i bits = _mm256_permutevar8x32_epi32(
            interleaved, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7));
        return Float8(_mm256_cvtepi32_ps(bits)) * (1.0f / 16777216.0f);
    }

private:
    U64x8 key_;  // hash of (seed, pixel, sample) per lane
};

// The watertight triangle test's rare case, 8 lanes wide: where an edge function rounded to
// exactly zero (`on_edge`), recompute u, v, w of those lanes in double (triangle.h's
// edge_function_exact), so the sign is exact there too.
inline void redo_edges_exactly(Mask8 on_edge, Float8 ax, Float8 ay, Float8 bx, Float8 by,
                               Float8 cx, Float8 cy, Float8& u, Float8& v, Float8& w) {
    float uvw[3][kLanes];
    u.store(uvw[0]);
    v.store(uvw[1]);
    w.store(uvw[2]);
    for (int lane = 0; lane < kLanes; ++lane) {
        if (!(on_edge.bits() >> lane & 1)) continue;
        const float lax = ax.lane(lane), lay = ay.lane(lane), lbx = bx.lane(lane);
        const float lby = by.lane(lane), lcx = cx.lane(lane), lcy = cy.lane(lane);
        uvw[0][lane] = static_cast<float>(edge_function_exact(lcx, lcy, lbx, lby));
        uvw[1][lane] = static_cast<float>(edge_function_exact(lax, lay, lcx, lcy));
        uvw[2][lane] = static_cast<float>(edge_function_exact(lbx, lby, lax, lay));
    }
    u = Float8::load(uvw[0]);
    v = Float8::load(uvw[1]);
    w = Float8::load(uvw[2]);
}
