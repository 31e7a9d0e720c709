// The path pool as a structure of arrays (SoA): one array per scalar field, so that the
// threads of a warp, which work on neighbouring places of a queue, read and write
// neighbouring words, and a kernel that needs only some fields moves only those. The member
// functions are lab 06's (path_pool.cuh lists them; path_pool_aos.cuh implements them as an
// array of structures): the kernels read an item "as one struct" (paths.load(k)) whichever
// layout is behind it, the way pbrt-v4's generated SOA types do, so lab 06's kernels run
// unchanged on this pool.
//!
//! Lab 07 students write the three arrays (the region between BEGIN/END SOLUTION);
//! tools/skeletons.py turns this file into labs/07-soa/skeleton/path_pool_soa.cuh.
#pragma once

#include <path_pool.cuh>

// BEGIN SOLUTION
// A Vec3 per place as three float arrays.
struct Vec3Array {
    float *x, *y, *z;

    void carve(ArrayCarver& c) {
        x = c.take<float>();
        y = c.take<float>();
        z = c.take<float>();
    }
    __device__ Vec3 load(int i) const { return Vec3(x[i], y[i], z[i]); }
    __device__ void store(int i, Vec3 v) const {
        x[i] = v.x;
        y[i] = v.y;
        z[i] = v.z;
    }
};

struct RayArray {
    Vec3Array origin, direction;

    void carve(ArrayCarver& c) {
        origin.carve(c);
        direction.carve(c);
    }
    __device__ Ray load(int i) const { return {origin.load(i), direction.load(i)}; }
    __device__ void store(int i, const Ray& r) const {
        origin.store(i, r.origin);
        direction.store(i, r.direction);
    }
};

// The fields of AosPaths::Record, each in its own array: 12 words of 4 bytes per place.
struct SoaPaths {
    RayArray ray;
    Vec3Array throughput;
    int* slot;
    float* hit_t;  // PackedHit
    int* hit_primitive;

    void carve(ArrayCarver& c) {
        ray.carve(c);
        throughput.carve(c);
        slot = c.take<int>();
        hit_t = c.take<float>();
        hit_primitive = c.take<int>();
    }
    // find_closest_hits writes the hit before anyone reads it: store leaves it alone.
    __device__ void store(int k, const QueuedPath& p) const {
        ray.store(k, p.ray);
        throughput.store(k, p.throughput);
        slot[k] = p.slot;
    }
    __device__ QueuedPath load(int k) const { return {ray.load(k), throughput.load(k), slot[k]}; }
    __device__ Ray load_ray(int k) const { return ray.load(k); }
    __device__ void store_hit(int k, const Hit& h) const {
        const PackedHit packed = pack_hit(h);
        hit_t[k] = packed.t;
        hit_primitive[k] = packed.primitive;
    }
    __device__ Hit load_hit(int k) const { return unpack_hit({hit_t[k], hit_primitive[k]}); }
};

// The fields of AosShadowRays::Record: 11 words per place.
struct SoaShadowRays {
    RayArray ray;
    float* t_max;
    Vec3Array radiance;
    int* slot;

    void carve(ArrayCarver& c) {
        ray.carve(c);
        t_max = c.take<float>();
        radiance.carve(c);
        slot = c.take<int>();
    }
    __device__ void store(int k, const QueuedShadowRay& q) const {
        ray.store(k, q.shadow.ray);
        t_max[k] = q.shadow.t_max;
        radiance.store(k, q.shadow.radiance);
        slot[k] = q.slot;
    }
    __device__ QueuedShadowRay load(int k) const {
        return {{ray.load(k), t_max[k], radiance.load(k)}, slot[k]};
    }
};

struct SoaRadiance {
    Vec3Array sum;  // [slot]

    void carve(ArrayCarver& c) { sum.carve(c); }
    __device__ void start(int slot, Vec3 v) const { sum.store(slot, v); }
    __device__ void add(int slot, Vec3 v) const { sum.store(slot, sum.load(slot) + v); }
    __device__ Vec3 load(int slot) const { return sum.load(slot); }
};
// SKELETON
//> // TODO(lab07): the pool as a structure of arrays. Give SoaPaths, SoaShadowRays and
//> // SoaRadiance one array per scalar field of lab 06's records (path_pool_aos.cuh: a Ray, a
//> // Vec3 and a slot per queued path, and its PackedHit; the ShadowRay's fields and a slot
//> // per shadow ray; a Vec3 per slot of radiance; a Vec3 is three float arrays), each taken
//> // from the pool's one allocation in carve (ArrayCarver::take<T>() gives an array of T
//> // with one element per slot), and the member functions of path_pool_aos.cuh reading and
//> // writing them. Until then: nothing is stored and every load returns a default, a hit
//> // included (no hit), so no path gathers any radiance: the image is black.
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
