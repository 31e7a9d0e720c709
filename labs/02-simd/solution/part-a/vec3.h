// Lab 02 Part A: the course report's SIMD method. Vec3 keeps x, y, z in one 128-bit SSE
// register, the fourth lane padding, with exactly the interface of the scalar Vec3 of
// common/core/vec3.h. This folder comes first on the include path of every file of ./lab02a
// and ./lab02a-ref, so this file stands in for that one and the whole lab-01 path tracer
// compiles with it unchanged.
//
// Per lane the arithmetic is the scalar code's (same operations, same order, no fused
// multiply-add), so the image comes out the same; only the instructions differ. Whether they
// are faster is the question Part A asks: see handouts/02-simd.md.
//!
//! Lab 02 students write the regions between BEGIN/END SOLUTION; labkit/skeletons.py turns
//! this file into labs/02-simd/skeleton/part-a/vec3.h, where each region is scalar code that
//! is correct but not SIMD.
#pragma once

#include <cmath>

#include <immintrin.h>

#include <rt_hd.h>

// What this build's Vec3 is: printed in the run's summary (the "device" field).
// BEGIN SOLUTION
constexpr const char* kVec3Kind = "Vec3 on SSE";
// SKELETON
//> constexpr const char* kVec3Kind = "Vec3 scalar fallback, TODO(lab02) Part A";
// END SOLUTION

struct alignas(16) Vec3 {
    float x = 0, y = 0, z = 0;  // components; for colours: r, g, b
    float w = 0;                // padding lane: keeps loads aligned; stays 0 (see dot)

    Vec3() = default;
    constexpr Vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
    explicit constexpr Vec3(float s) : x(s), y(s), z(s) {}

    // Component by index 0..2; used where an axis is chosen at run time.
    float operator[](int i) const { return (&x)[i]; }

    // The four lanes as one SSE register (x in lane 0), and back. The compiler keeps a
    // Vec3 that only passes through these in a register.
    __m128 m128() const { return _mm_load_ps(&x); }
    static Vec3 from(__m128 v) {
        Vec3 r;
        _mm_store_ps(&r.x, v);
        return r;
    }
};

static_assert(sizeof(Vec3) == 16, "x, y, z and one padding lane: one SSE register");

// Worked examples: one instruction each for four lanes (the padding lane does 0 + 0).
inline Vec3 operator+(Vec3 a, Vec3 b) { return Vec3::from(_mm_add_ps(a.m128(), b.m128())); }
inline Vec3 operator-(Vec3 a, Vec3 b) { return Vec3::from(_mm_sub_ps(a.m128(), b.m128())); }

inline Vec3 operator-(Vec3 a) {
    // BEGIN SOLUTION
    return Vec3::from(_mm_xor_ps(a.m128(), _mm_set1_ps(-0.0f)));  // flip the sign bits
    // SKELETON
    //> return {-a.x, -a.y, -a.z};  // TODO(lab02) Part A: one _mm_xor_ps with the sign bits
    // END SOLUTION
}

inline Vec3 operator*(Vec3 a, Vec3 b) {
    // BEGIN SOLUTION
    return Vec3::from(_mm_mul_ps(a.m128(), b.m128()));
    // SKELETON
    //> return {a.x * b.x, a.y * b.y, a.z * b.z};  // TODO(lab02) Part A: _mm_mul_ps
    // END SOLUTION
}

inline Vec3 operator*(Vec3 a, float s) {
    // BEGIN SOLUTION
    // Zero in the padding lane, so that lane stays 0 even when s is infinite or NaN.
    return Vec3::from(_mm_mul_ps(a.m128(), _mm_setr_ps(s, s, s, 0.0f)));
    // SKELETON
    //> return {a.x * s, a.y * s, a.z * s};  // TODO(lab02) Part A: _mm_mul_ps by (s, s, s, 0)
    // END SOLUTION
}

inline Vec3 operator*(float s, Vec3 a) { return a * s; }
inline Vec3 operator/(Vec3 a, float s) { return a * (1.0f / s); }
inline Vec3& operator+=(Vec3& a, Vec3 b) { return a = a + b; }
inline Vec3& operator*=(Vec3& a, Vec3 b) { return a = a * b; }
inline Vec3& operator*=(Vec3& a, float s) { return a = a * s; }

// (a.x*b.x + a.y*b.y) + a.z*b.z, rounded as the scalar dot() rounds.
inline float dot(Vec3 a, Vec3 b) {
    // BEGIN SOLUTION
    // Three useful products in four lanes, then a horizontal sum: two shuffles, two adds.
    // With the padding lanes 0 the sum is (xx + yy) + (zz + 0), the scalar order exactly.
    const __m128 p = _mm_mul_ps(a.m128(), b.m128());
    const __m128 pairs = _mm_add_ps(p, _mm_shuffle_ps(p, p, _MM_SHUFFLE(2, 3, 0, 1)));
    return _mm_cvtss_f32(_mm_add_ss(pairs, _mm_movehl_ps(pairs, pairs)));
    // SKELETON
    //> // TODO(lab02) Part A: _mm_mul_ps, then a horizontal sum of lanes 0..2 with shuffles
    //> // (_mm_shuffle_ps, _mm_movehl_ps) and adds, or _mm_dp_ps (SSE4.1). Keep the order
    //> // (xx + yy) + zz and the image stays the scalar one.
    //> return a.x * b.x + a.y * b.y + a.z * b.z;
    // END SOLUTION
}

inline Vec3 cross(Vec3 a, Vec3 b) {
    // BEGIN SOLUTION
    // a.yzx * b.zxy - a.zxy * b.yzx: four shuffles to line the lanes up.
    const __m128 va = a.m128(), vb = b.m128();
    const __m128 a_yzx = _mm_shuffle_ps(va, va, _MM_SHUFFLE(3, 0, 2, 1));
    const __m128 b_zxy = _mm_shuffle_ps(vb, vb, _MM_SHUFFLE(3, 1, 0, 2));
    const __m128 a_zxy = _mm_shuffle_ps(va, va, _MM_SHUFFLE(3, 1, 0, 2));
    const __m128 b_yzx = _mm_shuffle_ps(vb, vb, _MM_SHUFFLE(3, 0, 2, 1));
    return Vec3::from(_mm_sub_ps(_mm_mul_ps(a_yzx, b_zxy), _mm_mul_ps(a_zxy, b_yzx)));
    // SKELETON
    //> // TODO(lab02) Part A: a.yzx * b.zxy - a.zxy * b.yzx, lining lanes up with
    //> // _mm_shuffle_ps(v, v, _MM_SHUFFLE(3, 0, 2, 1)) (yzx) and (3, 1, 0, 2) (zxy).
    //> return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    // END SOLUTION
}

inline float length_squared(Vec3 a) { return dot(a, a); }
inline float length(Vec3 a) { return sqrtf(dot(a, a)); }
inline Vec3 normalize(Vec3 a) { return a * (1.0f / length(a)); }

inline Vec3 abs(Vec3 a) {
    // BEGIN SOLUTION
    return Vec3::from(_mm_andnot_ps(_mm_set1_ps(-0.0f), a.m128()));  // clear the sign bits
    // SKELETON
    //> return {fabsf(a.x), fabsf(a.y), fabsf(a.z)};  // TODO(lab02) Part A: _mm_andnot_ps
    // END SOLUTION
}

// Scalar on purpose: a horizontal maximum of 3 lanes costs more shuffles than it saves.
inline float min_float(float a, float b) { return a < b ? a : b; }
inline float max_float(float a, float b) { return a > b ? a : b; }
inline float max_component(Vec3 a) { return max_float(a.x, max_float(a.y, a.z)); }
inline bool is_black(Vec3 a) { return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f; }

// Mirror reflection of incoming direction d about normal n (n unit length).
inline Vec3 reflect(Vec3 d, Vec3 n) { return d - n * (2.0f * dot(d, n)); }

// Two unit vectors that complete n (unit) to an orthonormal basis (Duff et al. 2017). Scalar
// code through the members: each lane needs a different formula.
inline void orthonormal_basis(Vec3 n, Vec3& t, Vec3& b) {
    const float sign = copysignf(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float c = n.x * n.y * a;
    t = {1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
}
