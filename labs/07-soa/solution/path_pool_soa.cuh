// The path pool as a structure of arrays (SoA): one array per scalar field, so that the
// threads of a warp, which work on paths of neighbouring slots, read and write neighbouring
// words, and a kernel that needs only some fields moves only those. The member functions
// are lab 06's AosPathPool's (path_pool_aos.cuh): the kernels read a field "as one struct"
// (pool.load_path(i)) whichever layout is behind it, the way pbrt-v4's generated SOA types
// do, so lab 06's kernels run unchanged on this pool.
//!
//! Lab 07 students write SoaPathPool (the region between BEGIN/END SOLUTION);
//! tools/skeletons.py turns this file into labs/07-soa/skeleton/path_pool_soa.cuh.
#pragma once

#include <cstddef>
#include <cstdint>

#include <path_tracer.h>

#include "packed_hit.cuh"

// Lays arrays out one after another in one allocation, each on a 256-byte boundary (so every
// warp's access to it starts on a cache line). With a null base it only measures.
class ArrayCarver {
public:
    ArrayCarver(void* base, int slots) : base_(static_cast<char*>(base)), slots_(slots) {}
    template <class T>
    T* take() {
        offset_ = (offset_ + 255) / 256 * 256;
        T* array = base_ ? reinterpret_cast<T*>(base_ + offset_) : nullptr;
        offset_ += sizeof(T) * static_cast<size_t>(slots_);
        return array;
    }
    size_t bytes() const { return offset_; }

private:
    char* base_;
    int slots_;
    size_t offset_ = 0;
};

// BEGIN SOLUTION
// A Vec3 per slot as three float arrays.
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

// The fields of AosPathPool::Record, each in its own array: 23 words of 4 bytes per path
// (the AoS record's 112 bytes hold the same 92 and 20 bytes of padding that keep its rows
// aligned).
struct SoaPathPool {
    RayArray ray;                // PathState, less what the queues say (bounce, alive)
    Vec3Array throughput, radiance;
    float* hit_t;                // PackedHit
    int* hit_primitive;
    RayArray shadow_ray;         // ShadowRay
    float* shadow_t_max;
    Vec3Array shadow_radiance;

    static constexpr const char* kName = "SoA";
    // The arrays one after another, in the order above.
    static SoaPathPool laid_out(ArrayCarver& c) {
        SoaPathPool p;
        p.ray.carve(c);
        p.throughput.carve(c);
        p.radiance.carve(c);
        p.hit_t = c.take<float>();
        p.hit_primitive = c.take<int>();
        p.shadow_ray.carve(c);
        p.shadow_t_max = c.take<float>();
        p.shadow_radiance.carve(c);
        return p;
    }
    static SoaPathPool carve(void* memory, int slots) {
        ArrayCarver c(memory, slots);
        return laid_out(c);
    }
    static size_t bytes_for(int slots) {
        ArrayCarver c(nullptr, slots);
        laid_out(c);
        return c.bytes();
    }

    __device__ void start_path(int i, const PathState& p) const {
        ray.store(i, p.ray);
        throughput.store(i, p.throughput);
        radiance.store(i, p.radiance);
    }
    __device__ PathState load_path(int i, int bounce) const {
        return {ray.load(i), throughput.load(i), Vec3(0.0f), bounce, true};
    }
    __device__ void store_path(int i, const PathState& p) const {
        ray.store(i, p.ray);
        throughput.store(i, p.throughput);
    }
    __device__ Ray load_ray(int i) const { return ray.load(i); }
    __device__ Hit load_hit(int i) const { return unpack_hit({hit_t[i], hit_primitive[i]}); }
    __device__ void store_hit(int i, const Hit& h) const {
        const PackedHit packed = pack_hit(h);
        hit_t[i] = packed.t;
        hit_primitive[i] = packed.primitive;
    }
    __device__ ShadowRay load_shadow(int i) const {
        return {shadow_ray.load(i), shadow_t_max[i], shadow_radiance.load(i)};
    }
    __device__ void store_shadow(int i, const ShadowRay& s) const {
        shadow_ray.store(i, s.ray);
        shadow_t_max[i] = s.t_max;
        shadow_radiance.store(i, s.radiance);
    }
    __device__ Vec3 load_radiance(int i) const { return radiance.load(i); }
    __device__ void add_radiance(int i, Vec3 r) const { radiance.store(i, radiance.load(i) + r); }
};
// SKELETON
//> // TODO(lab07): the pool as a structure of arrays. Give SoaPathPool one array per scalar
//> // field of lab 06's AosPathPool::Record (Ray, PackedHit, throughput, radiance, the shadow
//> // ray's fields; a Vec3 is three float arrays), carved out of the one allocation with
//> // ArrayCarver (bytes_for measures the same layout with a null base), and the same member
//> // functions reading and writing them (path_pool_aos.cuh says what each one does).
//> // Until then: nothing is stored and every load returns a default, a hit included (no hit),
//> // so no path keeps any radiance: the image is black.
//> struct SoaPathPool {
//>     static constexpr const char* kName = "SoA";
//>     static SoaPathPool carve(void*, int) { return {}; }
//>     static size_t bytes_for(int slots) { return static_cast<size_t>(slots); }
//>
//>     __device__ void start_path(int, const PathState&) const {}
//>     __device__ PathState load_path(int, int bounce) const { return {Ray{}, Vec3(0.0f), Vec3(0.0f), bounce, true}; }
//>     __device__ void store_path(int, const PathState&) const {}
//>     __device__ Ray load_ray(int) const { return {}; }
//>     __device__ Hit load_hit(int) const { return {}; }
//>     __device__ void store_hit(int, const Hit&) const {}
//>     __device__ ShadowRay load_shadow(int) const { return {}; }
//>     __device__ void store_shadow(int, const ShadowRay&) const {}
//>     __device__ Vec3 load_radiance(int) const { return Vec3(0.0f); }
//>     __device__ void add_radiance(int, Vec3) const {}
//> };
// END SOLUTION
