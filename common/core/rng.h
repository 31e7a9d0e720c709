// Counter-based random numbers: every value is a pure function of
// (seed, pixel, sample, dimension), so no generator state is ever shared between threads,
// ranks or GPU threads, and any parallel schedule reproduces the serial image bit for bit.
#pragma once

#include <cstdint>

#include <rt_hd.h>

// Stafford's "Mix13" 64-bit finaliser (as in SplitMix64): a bijection whose output bits
// each depend on every input bit.
RT_HD inline uint64_t mix64(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

// The 24 high bits of a 64-bit word as a float in [0, 1): exactly representable, never 1.
RT_HD inline float unit_float(uint64_t bits) {
    return static_cast<float>(static_cast<uint32_t>(bits >> 40)) * (1.0f / 16777216.0f);
}

// Which dimension each decision of a path draws: fixed by position in the path, not by
// the order of calls, so a wavefront renderer that splits the path into kernels draws the
// same numbers as the serial one.
constexpr uint32_t kDimPixelX = 0;  // jitter inside the pixel
constexpr uint32_t kDimPixelY = 1;
constexpr uint32_t kDimsPerBounce = 2;
RT_HD constexpr uint32_t bounce_dimension(int bounce, uint32_t k) {
    return 2u + kDimsPerBounce * static_cast<uint32_t>(bounce) + k;
}

// The random numbers of one camera path: dimension d of (seed, pixel, sample).
class SampleStream {
public:
    RT_HD SampleStream(uint64_t seed, uint64_t pixel, uint64_t sample)
        : key_(mix64(mix64(mix64(seed ^ 0x9e3779b97f4a7c15ull) ^ pixel) ^ sample)) {}

    // The value in [0, 1) of one dimension, independent of every other dimension.
    RT_HD float at(uint32_t dimension) const {
        return unit_float(mix64(key_ + 0x9e3779b97f4a7c15ull * (dimension + 1ull)));
    }

private:
    uint64_t key_;  // hash of (seed, pixel, sample)
};
