// The closest hit as the path pools keep it between find_closest_hits and shade_hits: the
// distance and one primitive number, 8 bytes instead of the core's 12 (Hit keeps a sphere and
// a triangle index, one of them -1). Every byte a stage moves per path counts: the wavefront
// kernels are bound by memory traffic (handouts/06-cuda-split.md).
#pragma once

#include <path_tracer.h>

// primitive: sphere i is i, triangle j is -2 - j, nothing hit is -1.
struct PackedHit {
    float t;
    int primitive;
};

__host__ __device__ inline PackedHit pack_hit(const Hit& hit) {
    return {hit.t, hit.sphere >= 0 ? hit.sphere : (hit.triangle >= 0 ? -2 - hit.triangle : -1)};
}

__host__ __device__ inline Hit unpack_hit(PackedHit packed) {
    Hit hit;
    hit.t = packed.t;
    if (packed.primitive >= 0) hit.sphere = packed.primitive;
    if (packed.primitive <= -2) hit.triangle = -2 - packed.primitive;
    return hit;
}
