// Lab 07: your copy, yours to edit. Every place to fill in is marked TODO(lab07).
// The path pool as a structure of arrays (SoA): one array per scalar field, so that the
// threads of a warp, which work on neighbouring places of a queue, read and write
// neighbouring words, and a kernel that needs only some fields moves only those. The member
// functions are lab 06's (path_pool.cuh lists them; path_pool_aos.cuh implements them as an
// array of structures): the kernels read an item "as one struct" (paths.load(k)) whichever
// layout is behind it, the way pbrt-v4's generated SOA types do, so lab 06's kernels run
// unchanged on this pool.
#pragma once

#include <path_pool.cuh>

// TODO(lab07): the pool as a structure of arrays. Give SoaPaths, SoaShadowRays and
// SoaRadiance one array per scalar field of lab 06's records (path_pool_aos.cuh: a Ray, a
// Vec3 and a slot per queued path, and its PackedHit; the ShadowRay's fields and a slot
// per shadow ray; a Vec3 per slot of radiance; a Vec3 is three float arrays), each taken
// from the pool's one allocation in carve (ArrayCarver::take<T>() gives an array of T
// with one element per place; take_arrays<T>(n, stride) n of them at a fixed stride
// from one pointer, which keeps the kernels' registers down: handouts/07-soa.md), and the
// member functions of path_pool_aos.cuh reading and writing them. Until then: nothing is
// stored and every load returns a default, a hit included (no hit), so no path gathers
// any radiance: the image is black.
struct SoaPaths {
    void carve(ArrayCarver& c) { c.take<char>(); }
    __device__ void store(int, const QueuedPath&) const {}
    __device__ QueuedPath load(int) const { return {Ray{}, Vec3(0.0f), 0}; }
    __device__ Ray load_ray(int) const { return {}; }
    __device__ void store_hit(int, const Hit&) const {}
    __device__ Hit load_hit(int) const { return {}; }
};

struct SoaShadowRays {
    void carve(ArrayCarver& c) { c.take<char>(); }
    __device__ void store(int, const QueuedShadowRay&) const {}
    __device__ QueuedShadowRay load(int) const { return {{Ray{}, 0.0f, Vec3(0.0f)}, 0}; }
};

struct SoaRadiance {
    void carve(ArrayCarver& c) { c.take<char>(); }
    __device__ void start(int, Vec3) const {}
    __device__ void add(int, Vec3) const {}
    __device__ Vec3 load(int) const { return Vec3(0.0f); }
};

struct SoaPathPool {
    static constexpr const char* kName = "SoA";
    using Paths = SoaPaths;
    using ShadowRays = SoaShadowRays;
    using Radiance = SoaRadiance;
};
