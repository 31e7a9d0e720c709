// Three-component vector of `real` (real.h: float, or double in the double build): points,
// directions and RGB radiance alike.
// Lab 02 Part A's SSE Vec3 (labs/02-simd/solution/part-a/vec3.h) stands in for this file by coming
// first on the include path.
#pragma once

#include <cmath>

#include <real.h>

struct Vec3 {
    real x = 0, y = 0, z = 0;  // components; for colours: r, g, b

    Vec3() = default;
    RT_HD constexpr Vec3(real x_, real y_, real z_) : x(x_), y(y_), z(z_) {}
    RT_HD explicit constexpr Vec3(real s) : x(s), y(s), z(s) {}

    // Component by index 0..2; used where an axis is chosen at run time. On the CPU an
    // indexed load beats a chain of selects; on the GPU indexing would spill to local memory.
    RT_HD real operator[](int i) const {
#if defined(__CUDA_ARCH__)
        return i == 0 ? x : (i == 1 ? y : z);
#else
        return (&x)[i];
#endif
    }
};

RT_HD inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
RT_HD inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
RT_HD inline Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
RT_HD inline Vec3 operator*(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
RT_HD inline Vec3 operator*(Vec3 a, real s) { return {a.x * s, a.y * s, a.z * s}; }
RT_HD inline Vec3 operator*(real s, Vec3 a) { return a * s; }
RT_HD inline Vec3 operator/(Vec3 a, real s) { return a * (real(1) / s); }
RT_HD inline Vec3& operator+=(Vec3& a, Vec3 b) { return a = a + b; }
RT_HD inline Vec3& operator*=(Vec3& a, Vec3 b) { return a = a * b; }
RT_HD inline Vec3& operator*=(Vec3& a, real s) { return a = a * s; }

RT_HD inline real dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
RT_HD inline Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
RT_HD inline real length_squared(Vec3 a) { return dot(a, a); }
RT_HD inline real length(Vec3 a) { return sqrt_real(dot(a, a)); }
RT_HD inline Vec3 normalize(Vec3 a) { return a * (real(1) / length(a)); }
RT_HD inline Vec3 abs(Vec3 a) { return {fabs_real(a.x), fabs_real(a.y), fabs_real(a.z)}; }
// Plain comparisons rather than fminf/fmaxf, which g++ calls out of line (NaN rules).
RT_HD inline real min_float(real a, real b) { return a < b ? a : b; }
RT_HD inline real max_float(real a, real b) { return a > b ? a : b; }
RT_HD inline real max_component(Vec3 a) { return max_float(a.x, max_float(a.y, a.z)); }
RT_HD inline bool is_black(Vec3 a) { return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f; }

// Mirror reflection of incoming direction d about normal n (n unit length).
RT_HD inline Vec3 reflect(Vec3 d, Vec3 n) { return d - n * (2.0f * dot(d, n)); }

// Two unit vectors that complete n (unit) to an orthonormal basis, without a branch on a
// threshold (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
RT_HD inline void orthonormal_basis(Vec3 n, Vec3& t, Vec3& b) {
    const real sign = copysign_real(real(1), n.z);
    const real a = real(-1) / (sign + n.z);
    const real c = n.x * n.y * a;
    t = {1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
}
