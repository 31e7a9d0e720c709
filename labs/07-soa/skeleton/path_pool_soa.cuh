// Lab 07: your copy, yours to edit. Every place to fill in is marked TODO(lab07).
// The path pool as a structure of arrays (SoA): one array per scalar field, so that the
// threads of a warp, which work on paths of neighbouring slots, read and write neighbouring
// words, and a kernel that needs only some fields moves only those. The member functions
// are lab 06's AosPathPool's (path_pool_aos.cuh): the kernels read a field "as one struct"
// (pool.load_path(i)) whichever layout is behind it, the way pbrt-v4's generated SOA types
// do, so lab 06's kernels run unchanged on this pool.
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

// TODO(lab07): the pool as a structure of arrays. Give SoaPathPool one array per scalar
// field of lab 06's AosPathPool::Record (Ray, PackedHit, throughput, radiance, the shadow
// ray's fields; a Vec3 is three float arrays), carved out of the one allocation with
// ArrayCarver (bytes_for measures the same layout with a null base), and the same member
// functions reading and writing them (path_pool_aos.cuh says what each one does).
// Until then: nothing is stored and every load returns a default, a hit included (no hit),
// so no path keeps any radiance: the image is black.
struct SoaPathPool {
    static constexpr const char* kName = "SoA";
    static SoaPathPool carve(void*, int) { return {}; }
    static size_t bytes_for(int slots) { return static_cast<size_t>(slots); }

    __device__ void start_path(int, const PathState&) const {}
    __device__ PathState load_path(int, int bounce) const { return {Ray{}, Vec3(0.0f), Vec3(0.0f), bounce, true}; }
    __device__ void store_path(int, const PathState&) const {}
    __device__ Ray load_ray(int) const { return {}; }
    __device__ Hit load_hit(int) const { return {}; }
    __device__ void store_hit(int, const Hit&) const {}
    __device__ ShadowRay load_shadow(int) const { return {}; }
    __device__ void store_shadow(int, const ShadowRay&) const {}
    __device__ Vec3 load_radiance(int) const { return Vec3(0.0f); }
    __device__ void add_radiance(int, Vec3) const {}
};
