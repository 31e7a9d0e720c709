// The closest hit as the path pools keep it between find_closest_hits and shade_hits: the
// distance and one primitive number, 8 bytes instead of the core's 12 (Hit keeps a kind and an
// index). Every byte a stage moves per path counts: the wavefront kernels are bound by memory
// traffic (handouts/06-cuda-split.md).
#pragma once

#include <path_tracer.h>

// primitive: index << kKindBits | (kind - 1) for a hit, -1 for none. kKindBits numbers every
// kind of AllPrimitives (primitive_kinds.h): two bits for four kinds, and an index range that
// shrinks by half with each bit a new kind costs.
constexpr int kKindBits = bits_to_number(AllPrimitives::kCount);
constexpr int kKindMask = (1 << kKindBits) - 1;

struct PackedHit {
    float t;
    int primitive;
};
static_assert(sizeof(PackedHit) == 8, "a packed hit is two words");

__host__ __device__ inline PackedHit pack_hit(const Hit& hit) {
    const int kind = static_cast<int>(hit.kind) - 1;
    return {static_cast<float>(hit.t), hit.found() ? hit.index << kKindBits | kind : -1};
}

__host__ __device__ inline Hit unpack_hit(PackedHit packed) {
    Hit hit;
    hit.t = packed.t;
    if (packed.primitive >= 0) {
        hit.kind = static_cast<PrimitiveKind>((packed.primitive & kKindMask) + 1);
        hit.index = packed.primitive >> kKindBits;
    }
    return hit;
}
