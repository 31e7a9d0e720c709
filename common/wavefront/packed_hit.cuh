// The closest hit as the path pools keep it between find_closest_hits and shade_hits: the
// distance and one primitive number, 8 bytes instead of the core's 12 (Hit keeps a kind and an
// index). Every byte a stage moves per path counts: the wavefront kernels are bound by memory
// traffic (handouts/06-cuda-split.md).
#pragma once

#include <path_tracer.h>

// primitive: index * 4 + (kind - 1) for a hit (kinds Sphere..Rect are 1..4), -1 for none.
struct PackedHit {
    float t;
    int primitive;
};
static_assert(sizeof(PackedHit) == 8, "a packed hit is two words");
static_assert(static_cast<int>(PrimitiveKind::Rect) - 1 < 4, "four kinds fit in two bits");

__host__ __device__ inline PackedHit pack_hit(const Hit& hit) {
    const int kind = static_cast<int>(hit.kind) - 1;
    return {static_cast<float>(hit.t), hit.found() ? hit.index * 4 + kind : -1};
}

__host__ __device__ inline Hit unpack_hit(PackedHit packed) {
    Hit hit;
    hit.t = packed.t;
    if (packed.primitive >= 0) {
        hit.kind = static_cast<PrimitiveKind>((packed.primitive & 3) + 1);
        hit.index = packed.primitive >> 2;
    }
    return hit;
}
