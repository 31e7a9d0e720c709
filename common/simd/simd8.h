// Lab 02 Part B: 8-lane values for AVX2, and (through lane_math.h) the renderer's math on them.
//
// Float8 holds 8 floats (one __m256), Mask8 a true/false per lane, Int8 8 ints. Every
// operator is one named intrinsic, so what the hardware does stays visible. simd16.h is the
// same interface on 16 AVX-512 lanes; lane_math.h and the packet tracer are written once over
// either (a template parameter F: Float8 or Float16), so the width is chosen at build time.
//
// Per lane, each function does exactly the scalar function's operations in the scalar
// function's order, and never a fused multiply-add (the intrinsics below are separate
// multiplies and adds; the build's -ffp-contract=off keeps the compiler from fusing them).
// So a lane computes the same bits as the scalar code, sin and cos included (sincos_2pi in
// lane_math.h is material.h's, lane by lane), and lab 02's image is lab 01's, bit for bit.
#pragma once

#if !defined(__AVX2__) || !defined(__FMA__)
#error "simd8.h needs AVX2: compile this file with -mavx2 -mfma (labs/02-simd/lab.mk does)"
#endif

#include <immintrin.h>

#include <cstdint>

#include <vec3.h>

struct Mask8;
struct Int8;
struct U64x8;
class Compress8;

// ---- floats ----------------------------------------------------------------------------

// 8 floats. A plain float converts to all 8 lanes.
struct Float8 {
    using Mask = Mask8;  // what its comparisons give
    using Int = Int8;    // indices of the same width
    using U64 = U64x8;   // 8 unsigned 64-bit integers (random numbers)
    using Compress = Compress8;  // moves chosen lanes to the front
    static constexpr int kLanes = 8;

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
    unsigned bits() const { return static_cast<unsigned>(_mm256_movemask_ps(m)); }  // bit i: lane i
};

inline Mask8 operator&(Mask8 a, Mask8 b) { return {_mm256_and_ps(a.m, b.m)}; }
inline Mask8 operator|(Mask8 a, Mask8 b) { return {_mm256_or_ps(a.m, b.m)}; }
inline Mask8 operator~(Mask8 a) { return {_mm256_xor_ps(a.m, Mask8::all().m)}; }
inline Mask8 and_not(Mask8 a, Mask8 b) { return {_mm256_andnot_ps(b.m, a.m)}; }  // a & ~b
inline Mask8& operator&=(Mask8& a, Mask8 b) { return a = a & b; }
inline Mask8& operator|=(Mask8& a, Mask8 b) { return a = a | b; }
inline bool any(Mask8 a) { return _mm256_testz_ps(a.m, a.m) == 0; }
inline bool none(Mask8 a) { return _mm256_testz_ps(a.m, a.m) != 0; }

// ---- float arithmetic ------------------------------------------------------------------

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
// !(a <= b) and !(a >= b): true where a lane holds NaN, as the negated scalar test is.
inline Mask8 not_less_equal(Float8 a, Float8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_NLE_UQ)}; }
inline Mask8 not_greater_equal(Float8 a, Float8 b) {
    return {_mm256_cmp_ps(a.v, b.v, _CMP_NGE_UQ)};
}

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
// rint: to the nearest integer, ties to even (the scalar code's rounding mode).
inline Float8 round_to_nearest(Float8 a) {
    return _mm256_round_ps(a.v, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
}

// ---- ints (indices) --------------------------------------------------------------------

struct Int8 {
    __m256i v;

    Int8() = default;
    Int8(__m256i v_) : v(v_) {}  // NOLINT: implicit by design
    explicit Int8(int s) : v(_mm256_set1_epi32(s)) {}  // broadcast
    static Int8 load(const int32_t* p) {
        return {_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p))};
    }
    void store(int32_t* p) const { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v); }
    int lane(int i) const {
        return _mm256_cvtsi256_si32(_mm256_permutevar8x32_epi32(v, _mm256_set1_epi32(i)));
    }
};

inline Mask8 operator==(Int8 a, Int8 b) {
    return {_mm256_castsi256_ps(_mm256_cmpeq_epi32(a.v, b.v))};
}
inline Mask8 operator==(Int8 a, int b) { return a == Int8(b); }
inline Int8 operator+(Int8 a, int b) { return _mm256_add_epi32(a.v, _mm256_set1_epi32(b)); }
inline Int8 operator&(Int8 a, int b) { return _mm256_and_si256(a.v, _mm256_set1_epi32(b)); }
inline Int8 operator^(Int8 a, Int8 b) { return _mm256_xor_si256(a.v, b.v); }
inline Int8 operator>>(Int8 a, int bits) { return _mm256_srli_epi32(a.v, bits); }
inline Int8 select(Mask8 mask, Int8 a, Int8 b) {
    return _mm256_castps_si256(
        _mm256_blendv_ps(_mm256_castsi256_ps(b.v), _mm256_castsi256_ps(a.v), mask.m));
}
// static_cast<int>(a) of a float that holds an integer.
inline Int8 to_int(Float8 a) { return _mm256_cvtps_epi32(a.v); }

// ---- reading the scene -----------------------------------------------------------------

// v[k] lane by lane for a Vec3 that is the same in every lane: one in-lane permute of the 16
// bytes at &v, no selects. (Reads one float past v: the caller guarantees it exists.)
inline Float8 permuted(const Vec3& v, Int8 k) {
    const __m256 row = _mm256_broadcast_ps(reinterpret_cast<const __m128*>(&v.x));
    return _mm256_permutevar_ps(row, k.v);
}

// Per-lane fields of the scene's arrays: lane i reads (&first)[index_i * stride] where `mask`
// holds, 0 elsewhere.
inline Float8 gather(const float& first, int stride, Int8 index, Mask8 mask) {
    return _mm256_mask_i32gather_ps(_mm256_setzero_ps(), &first,
                                    _mm256_mullo_epi32(index.v, _mm256_set1_epi32(stride)), mask.m,
                                    4);
}
inline Int8 gather(const int& first, int stride, Int8 index, Mask8 mask) {
    return _mm256_mask_i32gather_epi32(_mm256_setzero_si256(), &first,
                                       _mm256_mullo_epi32(index.v, _mm256_set1_epi32(stride)),
                                       _mm256_castps_si256(mask.m), 4);
}

// ---- moving lanes together (compaction) ------------------------------------------------

// Moves the lanes of `keep` to the front, in order, and the others behind them: one
// permutation per mask, from a table of all 256, applied to every field of a packet.
class Compress8 {
public:
    explicit Compress8(Mask8 keep) {
        // Entry m packs the 8 source lanes for mask m, 4 bits each, lane 0 lowest.
        static const uint32_t* const table = [] {
            static uint32_t t[256];
            for (unsigned m = 0; m < 256; ++m) {
                uint32_t packed = 0;
                int at = 0;
                for (int pass = 0; pass < 2; ++pass) {
                    for (unsigned lane = 0; lane < 8; ++lane) {
                        if (((m >> lane) & 1u) == (pass == 0 ? 1u : 0u)) {
                            packed |= lane << (4 * at++);
                        }
                    }
                }
                t[m] = packed;
            }
            return t;
        }();
        const unsigned bits = keep.bits();
        count_ = __builtin_popcount(bits);
        index_ =
            _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32(static_cast<int>(table[bits])),
                                               _mm256_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28)),
                             _mm256_set1_epi32(15));
    }
    int count() const { return count_; }  // lanes kept
    Float8 operator()(Float8 a) const { return _mm256_permutevar8x32_ps(a.v, index_); }
    Int8 operator()(Int8 a) const { return _mm256_permutevar8x32_epi32(a.v, index_); }

private:
    __m256i index_;
    int count_;
};

// ---- 64-bit integers, for the random numbers --------------------------------------------

// 8 unsigned 64-bit integers, lanes 0-3 in lo and 4-7 in hi.
struct U64x8 {
    __m256i lo, hi;

    // Lane i: low | high << 32, from two arrays of 8 words.
    static U64x8 load(const uint32_t* low, const uint32_t* high) {
        const auto half = [](const uint32_t* l, const uint32_t* h) {
            const auto words = [](const uint32_t* w) {
                return _mm256_cvtepu32_epi64(_mm_loadu_si128(reinterpret_cast<const __m128i*>(w)));
            };
            const __m256i lo32 = words(l);
            const __m256i hi32 = words(h);
            return _mm256_or_si256(lo32, _mm256_slli_epi64(hi32, 32));
        };
        return {half(low, high), half(low + 4, high + 4)};
    }
    // first + i in lane i.
    static U64x8 sequence(uint64_t first) {
        const __m256i s = _mm256_set1_epi64x(static_cast<long long>(first));
        return {_mm256_add_epi64(s, _mm256_setr_epi64x(0, 1, 2, 3)),
                _mm256_add_epi64(s, _mm256_setr_epi64x(4, 5, 6, 7))};
    }
};

inline U64x8 operator+(U64x8 a, uint64_t b) {
    const __m256i s = _mm256_set1_epi64x(static_cast<long long>(b));
    return {_mm256_add_epi64(a.lo, s), _mm256_add_epi64(a.hi, s)};
}
inline U64x8 operator^(U64x8 a, uint64_t b) {
    const __m256i s = _mm256_set1_epi64x(static_cast<long long>(b));
    return {_mm256_xor_si256(a.lo, s), _mm256_xor_si256(a.hi, s)};
}

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
inline U64x8 mix64(U64x8 z) { return {mix64(z.lo), mix64(z.hi)}; }

// unit_float (rng.h) lane by lane: the top 24 bits of each word, as a float in [0, 1).
inline Float8 unit_float(U64x8 bits) {
    const __m256i lo = _mm256_srli_epi64(bits.lo, 40);
    const __m256i hi = _mm256_srli_epi64(bits.hi, 40);
    // 32-bit words (lo0, hi0, lo1, hi1, ...) -> (lo0, lo1, lo2, lo3, hi0, ..., hi3).
    const __m256i interleaved = _mm256_or_si256(lo, _mm256_slli_epi64(hi, 32));
    const __m256i words =
        _mm256_permutevar8x32_epi32(interleaved, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7));
    return Float8(_mm256_cvtepi32_ps(words)) * (1.0f / 16777216.0f);
}

#include <lane_math.h>

// The 8-lane names of lane_math.h's types.
using Vec3x8 = Vec3xN<Float8>;
using SampleStream8 = SampleStreamN<Float8>;

// material.h's sincos_2pi on 8 lanes (lane_math.h has it for any width).
inline void sincos_2pi8(Float8 u, Float8& s, Float8& c) { sincos_2pi(u, s, c); }
