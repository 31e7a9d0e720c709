// The path pool as a structure of arrays (SoA): one array per scalar field, so that the
// threads of a warp, which work on neighbouring places of a queue, read and write
// neighbouring words, and a kernel that needs only some fields moves only those. The member
// functions are lab 06's (path_pool.cuh lists them; path_pool_aos.cuh implements them as an
// array of structures): the kernels read an item "as one struct" (paths.load(k)) whichever
// layout is behind it, the way pbrt-v4's generated SOA types do, so lab 06's kernels run
// unchanged on this pool.
//!
//! Lab 07 students write the three arrays (the region between BEGIN/END SOLUTION);
//! labkit/skeletons.py turns this file into labs/07-soa/skeleton/path_pool_soa.cuh.
//! It stands in for this file in the lab's own build (first on the include path).
#pragma once

#include <path_pool.cuh>

// BEGIN SOLUTION
// The arrays of one kind of item: kFields arrays of 4-byte words, one per scalar field, one
// after another in the pool's allocation; field f of place k is words[f * stride + k]. One
// pointer and one stride rather than a pointer per array: a kernel keeps the addresses it
// uses in registers, and a pointer for each of the 38 arrays in shade_hits' arguments took
// it to 126 registers and a quarter of the GPU's threads (docs/gpu-tuning.md).
template <int kFields>
struct FieldArrays {
    float* words;
    int stride;

    void carve(ArrayCarver& c) { words = c.take_arrays<float>(kFields, stride); }
    __device__ float load(int field, int k) const { return words[field * stride + k]; }
    __device__ void store(int field, int k, float v) const { words[field * stride + k] = v; }
    __device__ Vec3 load3(int field, int k) const {
        return Vec3(load(field, k), load(field + 1, k), load(field + 2, k));
    }
    __device__ void store3(int field, int k, Vec3 v) const {
        store(field, k, v.x);
        store(field + 1, k, v.y);
        store(field + 2, k, v.z);
    }
    __device__ Ray load_ray(int field, int k) const {
        return {load3(field, k), load3(field + 3, k)};
    }
    __device__ void store_ray(int field, int k, const Ray& r) const {
        store3(field, k, r.origin);
        store3(field + 3, k, r.direction);
    }
};

// The fields of AosPaths::Record, each in its own array: 12 words per place.
struct SoaPaths {
    enum Field {
        kRay = 0,
        kThroughput = 6,
        kSlot = 9,
        kHitT = 10,
        kHitPrimitive = 11,
        kFields = 12
    };
    FieldArrays<kFields> a;

    void carve(ArrayCarver& c) { a.carve(c); }
    // find_closest_hits writes the hit before anyone reads it: store leaves it alone.
    __device__ void store(int k, const QueuedPath& p) const {
        a.store_ray(kRay, k, p.ray);
        a.store3(kThroughput, k, p.throughput);
        a.store(kSlot, k, __int_as_float(p.slot));
    }
    __device__ QueuedPath load(int k) const {
        return {a.load_ray(kRay, k), a.load3(kThroughput, k), __float_as_int(a.load(kSlot, k))};
    }
    __device__ Ray load_ray(int k) const { return a.load_ray(kRay, k); }
    __device__ void store_hit(int k, const Hit& h) const {
        const PackedHit packed = pack_hit(h);
        a.store(kHitT, k, packed.t);
        a.store(kHitPrimitive, k, __int_as_float(packed.primitive));
    }
    __device__ Hit load_hit(int k) const {
        return unpack_hit({a.load(kHitT, k), __float_as_int(a.load(kHitPrimitive, k))});
    }
};

// The fields of AosShadowRays::Record: 11 words per place.
struct SoaShadowRays {
    enum Field { kRay = 0, kTMax = 6, kRadiance = 7, kSlot = 10, kFields = 11 };
    FieldArrays<kFields> a;

    void carve(ArrayCarver& c) { a.carve(c); }
    __device__ void store(int k, const QueuedShadowRay& q) const {
        a.store_ray(kRay, k, q.shadow.ray);
        a.store(kTMax, k, q.shadow.t_max);
        a.store3(kRadiance, k, q.shadow.radiance);
        a.store(kSlot, k, __int_as_float(q.slot));
    }
    __device__ QueuedShadowRay load(int k) const {
        return {{a.load_ray(kRay, k), a.load(kTMax, k), a.load3(kRadiance, k)},
                __float_as_int(a.load(kSlot, k))};
    }
};

// Each slot's radiance: three arrays.
struct SoaRadiance {
    FieldArrays<3> a;

    void carve(ArrayCarver& c) { a.carve(c); }
    __device__ void start(int slot, Vec3 v) const { a.store3(0, slot, v); }
    __device__ void add(int slot, Vec3 v) const { a.store3(0, slot, a.load3(0, slot) + v); }
    __device__ Vec3 load(int slot) const { return a.load3(0, slot); }
};
// SKELETON
//> // TODO(lab07): the pool as a structure of arrays. Give SoaPaths, SoaShadowRays and
//> // SoaRadiance one array per scalar field of lab 06's records (path_pool_aos.cuh: a Ray, a
//> // Vec3 and a slot per queued path, and its PackedHit; the ShadowRay's fields and a slot
//> // per shadow ray; a Vec3 per slot of radiance; a Vec3 is three float arrays), each taken
//> // from the pool's one allocation in carve (ArrayCarver::take<T>() gives an array of T
//> // with one element per place; take_arrays<T>(n, stride) n of them at a fixed stride
//> // from one pointer, which keeps the kernels' registers down: handouts/07-soa.md), and the
//> // member functions of path_pool_aos.cuh reading and writing them. Until then: nothing is
//> // stored and every load returns a default, a hit included (no hit), so no path gathers
//> // any radiance: the image is black.
//> struct SoaPaths {
//>     void carve(ArrayCarver& c) { c.take<char>(); }
//>     __device__ void store(int, const QueuedPath&) const {}
//>     __device__ QueuedPath load(int) const { return {Ray{}, Vec3(0.0f), 0}; }
//>     __device__ Ray load_ray(int) const { return {}; }
//>     __device__ void store_hit(int, const Hit&) const {}
//>     __device__ Hit load_hit(int) const { return {}; }
//> };
//>
//> struct SoaShadowRays {
//>     void carve(ArrayCarver& c) { c.take<char>(); }
//>     __device__ void store(int, const QueuedShadowRay&) const {}
//>     __device__ QueuedShadowRay load(int) const { return {{Ray{}, 0.0f, Vec3(0.0f)}, 0}; }
//> };
//>
//> struct SoaRadiance {
//>     void carve(ArrayCarver& c) { c.take<char>(); }
//>     __device__ void start(int, Vec3) const {}
//>     __device__ void add(int, Vec3) const {}
//>     __device__ Vec3 load(int) const { return Vec3(0.0f); }
//> };
// END SOLUTION

struct SoaPathPool {
    static constexpr const char* kName = "SoA";
    using Paths = SoaPaths;
    using ShadowRays = SoaShadowRays;
    using Radiance = SoaRadiance;
};
