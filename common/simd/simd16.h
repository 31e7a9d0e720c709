// Lab 02 at the width of an AVX-512 core: Float16, Mask16, Int16, simd8.h's interface on 16
// lanes, so lane_math.h and the packet tracer, written once over their lane type, run 16
// paths per instruction. The differences are in here only: a mask is a mask register (one
// bit per lane, __mmask16) instead of a vector of all-ones lanes, 64-bit multiplies are one
// instruction (AVX512DQ), and compaction has its own instruction (VCOMPRESSPS).
//
// Only objects built with the AVX-512 flags include this (the Makefile's SIMD_AVX512_FLAGS),
// and only code that has checked the CPU (cpu_has_avx512, cpu_features.h) calls them.
#pragma once

#if !defined(__AVX512F__) || !defined(__AVX512DQ__) || !defined(__AVX512VL__) || \
    !defined(__AVX512BW__) || !defined(__FMA__)
#error "simd16.h needs AVX-512 (F, DQ, VL, BW): build this object with SIMD_AVX512_FLAGS"
#endif

// GCC 12 warns, wrongly, that the AVX-512 intrinsics' _mm512_undefined_ps() "may be used
// uninitialized" wherever one is inlined (GCC bug 105593, fixed in GCC 13). The warning is
// placed in the intrinsics' header, so silencing it there leaves it on for this code.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <immintrin.h>
#pragma GCC diagnostic pop

#include <cstdint>

#include <vec3.h>

struct Mask16;
struct Int16;
struct U64x16;
class Compress16;

// ---- floats ----------------------------------------------------------------------------

// 16 floats. A plain float converts to all 16 lanes.
struct Float16 {
    using Mask = Mask16;
    using Int = Int16;
    using U64 = U64x16;
    using Compress = Compress16;
    static constexpr int kLanes = 16;

    __m512 v;

    Float16() = default;
    Float16(__m512 v_) : v(v_) {}                  // NOLINT: implicit by design
    Float16(float s) : v(_mm512_set1_ps(s)) {}     // NOLINT: broadcast
    static Float16 load(const float* p) { return {_mm512_loadu_ps(p)}; }
    void store(float* p) const { _mm512_storeu_ps(p, v); }
    float lane(int i) const {
        return _mm512_cvtss_f32(_mm512_permutexvar_ps(_mm512_set1_epi32(i), v));
    }
};

// ---- masks -----------------------------------------------------------------------------

// A true/false per lane: one bit each, in a mask register.
struct Mask16 {
    __mmask16 m;

    static Mask16 all() { return {0xffff}; }
    static Mask16 none() { return {0}; }
    // Lanes 0..count-1 true (count 0..16).
    static Mask16 first(int count) {
        return {static_cast<__mmask16>(count >= 16 ? 0xffffu : (1u << count) - 1u)};
    }
    unsigned bits() const { return m; }  // bit i: lane i
};

inline Mask16 operator&(Mask16 a, Mask16 b) { return {static_cast<__mmask16>(a.m & b.m)}; }
inline Mask16 operator|(Mask16 a, Mask16 b) { return {static_cast<__mmask16>(a.m | b.m)}; }
inline Mask16 operator~(Mask16 a) { return {static_cast<__mmask16>(~a.m)}; }
inline Mask16 and_not(Mask16 a, Mask16 b) { return {static_cast<__mmask16>(a.m & ~b.m)}; }
inline Mask16& operator&=(Mask16& a, Mask16 b) { return a = a & b; }
inline Mask16& operator|=(Mask16& a, Mask16 b) { return a = a | b; }
inline bool any(Mask16 a) { return a.m != 0; }
inline bool none(Mask16 a) { return a.m == 0; }

// ---- float arithmetic ------------------------------------------------------------------

inline Float16 operator+(Float16 a, Float16 b) { return _mm512_add_ps(a.v, b.v); }
inline Float16 operator-(Float16 a, Float16 b) { return _mm512_sub_ps(a.v, b.v); }
inline Float16 operator*(Float16 a, Float16 b) { return _mm512_mul_ps(a.v, b.v); }
inline Float16 operator/(Float16 a, Float16 b) { return _mm512_div_ps(a.v, b.v); }
inline Float16 operator-(Float16 a) { return _mm512_xor_ps(a.v, _mm512_set1_ps(-0.0f)); }  // exact
inline Float16& operator+=(Float16& a, Float16 b) { return a = a + b; }
inline Float16& operator*=(Float16& a, Float16 b) { return a = a * b; }

// Comparisons: the _OQ predicates are false when a lane holds NaN, like scalar <, >, ==.
inline Mask16 operator<(Float16 a, Float16 b) { return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_LT_OQ)}; }
inline Mask16 operator<=(Float16 a, Float16 b) {
    return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_LE_OQ)};
}
inline Mask16 operator>(Float16 a, Float16 b) { return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_GT_OQ)}; }
inline Mask16 operator>=(Float16 a, Float16 b) {
    return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_GE_OQ)};
}
inline Mask16 operator==(Float16 a, Float16 b) {
    return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_EQ_OQ)};
}
inline Mask16 operator!=(Float16 a, Float16 b) {
    return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_NEQ_OQ)};
}
// !(a <= b) and !(a >= b): true where a lane holds NaN, as the negated scalar test is.
inline Mask16 not_less_equal(Float16 a, Float16 b) {
    return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_NLE_UQ)};
}
inline Mask16 not_greater_equal(Float16 a, Float16 b) {
    return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_NGE_UQ)};
}

// mask ? a : b in each lane.
inline Float16 select(Mask16 mask, Float16 a, Float16 b) {
    return _mm512_mask_blend_ps(mask.m, b.v, a.v);
}

inline Float16 sqrt(Float16 a) { return _mm512_sqrt_ps(a.v); }  // correctly rounded
inline Float16 abs(Float16 a) { return _mm512_andnot_ps(_mm512_set1_ps(-0.0f), a.v); }
// As MINPS/MAXPS: exactly min_float(a, b) / max_float(a, b) (simd8.h).
inline Float16 min(Float16 a, Float16 b) { return _mm512_min_ps(a.v, b.v); }
inline Float16 max(Float16 a, Float16 b) { return _mm512_max_ps(a.v, b.v); }
inline Float16 copysign(Float16 magnitude, Float16 sign) {
    const __m512 sign_bit = _mm512_set1_ps(-0.0f);
    return _mm512_or_ps(_mm512_andnot_ps(sign_bit, magnitude.v), _mm512_and_ps(sign_bit, sign.v));
}
// rint: to the nearest integer, ties to even.
inline Float16 round_to_nearest(Float16 a) {
    return _mm512_roundscale_ps(a.v, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
}

// ---- ints (indices) --------------------------------------------------------------------

struct Int16 {
    __m512i v;

    Int16() = default;
    Int16(__m512i v_) : v(v_) {}  // NOLINT: implicit by design
    explicit Int16(int s) : v(_mm512_set1_epi32(s)) {}  // broadcast
    static Int16 load(const int32_t* p) { return {_mm512_loadu_si512(p)}; }
    void store(int32_t* p) const { _mm512_storeu_si512(p, v); }
    int lane(int i) const {
        return _mm_cvtsi128_si32(
            _mm512_castsi512_si128(_mm512_permutexvar_epi32(_mm512_set1_epi32(i), v)));
    }
};

inline Mask16 operator==(Int16 a, Int16 b) { return {_mm512_cmpeq_epi32_mask(a.v, b.v)}; }
inline Mask16 operator==(Int16 a, int b) { return a == Int16(b); }
inline Int16 operator+(Int16 a, int b) { return _mm512_add_epi32(a.v, _mm512_set1_epi32(b)); }
inline Int16 operator&(Int16 a, int b) { return _mm512_and_si512(a.v, _mm512_set1_epi32(b)); }
inline Int16 operator^(Int16 a, Int16 b) { return _mm512_xor_si512(a.v, b.v); }
inline Int16 operator>>(Int16 a, int bits) {
    return _mm512_srli_epi32(a.v, static_cast<unsigned>(bits));
}
inline Int16 select(Mask16 mask, Int16 a, Int16 b) {
    return _mm512_mask_blend_epi32(mask.m, b.v, a.v);
}
inline Int16 to_int(Float16 a) { return _mm512_cvtps_epi32(a.v); }

// ---- reading the scene -----------------------------------------------------------------

// v[k] lane by lane for a Vec3 that is the same in every lane (reads 16 bytes at &v).
inline Float16 permuted(const Vec3& v, Int16 k) {
    const __m512 row = _mm512_broadcast_f32x4(_mm_loadu_ps(&v.x));
    return _mm512_permutevar_ps(row, k.v);
}

inline Float16 gather(const float& first, int stride, Int16 index, Mask16 mask) {
    return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), mask.m,
                                    _mm512_mullo_epi32(index.v, _mm512_set1_epi32(stride)), &first,
                                    4);
}
inline Int16 gather(const int& first, int stride, Int16 index, Mask16 mask) {
    return _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), mask.m,
                                       _mm512_mullo_epi32(index.v, _mm512_set1_epi32(stride)),
                                       &first, 4);
}

// ---- moving lanes together (compaction) ------------------------------------------------

// The lanes of `keep` to the front, in order (VCOMPRESSPS, register to register: compressing
// straight to memory is microcoded on some cores); the lanes behind them keep their old
// contents, so every lane of a stored packet holds a real path's numbers.
class Compress16 {
public:
    explicit Compress16(Mask16 keep) : keep_(keep.m), count_(__builtin_popcount(keep.m)) {}
    int count() const { return count_; }
    Float16 operator()(Float16 a) const { return _mm512_mask_compress_ps(a.v, keep_, a.v); }
    Int16 operator()(Int16 a) const { return _mm512_mask_compress_epi32(a.v, keep_, a.v); }

private:
    __mmask16 keep_;
    int count_;
};

// ---- 64-bit integers, for the random numbers --------------------------------------------

// 16 unsigned 64-bit integers, lanes 0-7 in lo and 8-15 in hi.
struct U64x16 {
    __m512i lo, hi;

    static U64x16 load(const uint32_t* low, const uint32_t* high) {
        const auto half = [](const uint32_t* l, const uint32_t* h) {
            const auto words = [](const uint32_t* w) {
                return _mm512_cvtepu32_epi64(
                    _mm256_loadu_si256(reinterpret_cast<const __m256i*>(w)));
            };
            const __m512i lo32 = words(l);
            const __m512i hi32 = words(h);
            return _mm512_or_si512(lo32, _mm512_slli_epi64(hi32, 32));
        };
        return {half(low, high), half(low + 8, high + 8)};
    }
    static U64x16 sequence(uint64_t first) {
        const __m512i s = _mm512_set1_epi64(static_cast<long long>(first));
        const __m512i lane = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7);
        const __m512i lane_8 = _mm512_add_epi64(lane, _mm512_set1_epi64(8));
        return {_mm512_add_epi64(s, lane), _mm512_add_epi64(s, lane_8)};
    }
};

inline U64x16 operator+(U64x16 a, uint64_t b) {
    const __m512i s = _mm512_set1_epi64(static_cast<long long>(b));
    return {_mm512_add_epi64(a.lo, s), _mm512_add_epi64(a.hi, s)};
}
inline U64x16 operator^(U64x16 a, uint64_t b) {
    const __m512i s = _mm512_set1_epi64(static_cast<long long>(b));
    return {_mm512_xor_si512(a.lo, s), _mm512_xor_si512(a.hi, s)};
}

// mix64 (rng.h) on 8 lanes: VPMULLQ multiplies 64 x 64 bits, as the scalar code does.
inline __m512i mix64(__m512i z) {
    z = _mm512_mullo_epi64(_mm512_xor_si512(z, _mm512_srli_epi64(z, 30)),
                           _mm512_set1_epi64(static_cast<long long>(0xbf58476d1ce4e5b9ull)));
    z = _mm512_mullo_epi64(_mm512_xor_si512(z, _mm512_srli_epi64(z, 27)),
                           _mm512_set1_epi64(static_cast<long long>(0x94d049bb133111ebull)));
    return _mm512_xor_si512(z, _mm512_srli_epi64(z, 31));
}
inline U64x16 mix64(U64x16 z) { return {mix64(z.lo), mix64(z.hi)}; }

// unit_float (rng.h) lane by lane.
inline Float16 unit_float(U64x16 bits) {
    const __m256i lo = _mm512_cvtepi64_epi32(_mm512_srli_epi64(bits.lo, 40));
    const __m256i hi = _mm512_cvtepi64_epi32(_mm512_srli_epi64(bits.hi, 40));
    const __m512i words = _mm512_inserti64x4(_mm512_castsi256_si512(lo), hi, 1);
    return Float16(_mm512_cvtepi32_ps(words)) * (1.0f / 16777216.0f);
}

#include <lane_math.h>

using Vec3x16 = Vec3xN<Float16>;
using SampleStream16 = SampleStreamN<Float16>;
