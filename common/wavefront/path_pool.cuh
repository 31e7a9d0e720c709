// The path pool: the device memory in which the stages hand paths to each other. What a
// stage leaves for the next is an item on that stage's queue (path_queue.cuh), copied in
// whole, and what each path gathers is a radiance sum per slot of the wave (wave.cuh):
//
//   paths[b % 2]   the queue of paths about to make interaction b: ray, throughput, slot,
//                  and the closest hit that find_closest_hits writes beside the ray
//   shadow_rays    the light samples interaction b asked for: shadow ray, slot
//   radiance       [slot]: what the path of each slot has gathered so far
//
// A path moves from paths[b % 2] to paths[(b + 1) % 2] when shade_hits pushes it on, so the
// queues stay dense and need no ids. What is not stored because the queues already say it:
// a path's bounce number (every path on queue b is about to make interaction b) and whether
// it is alive (it is alive while it is on a queue).
//
// A Layout says how each of the three is laid out in memory: lab 06's array of structures
// (path_pool_aos.cuh) or lab 07's structure of arrays. Each provides
//
//   Paths:       store(k, QueuedPath), load(k), load_ray(k), store_hit(k, Hit), load_hit(k)
//   ShadowRays:  store(k, QueuedShadowRay), load(k)
//   Radiance:    start(slot, Vec3), add(slot, Vec3), load(slot)
//   each:        carve(ArrayCarver&), its arrays taken from the pool's one allocation
//
// so the kernels (wavefront_kernels.cuh) are written once and read an item "as one struct"
// whichever layout is behind it, the way pbrt-v4's generated SOA types do.
#pragma once

#include <cstddef>

#include <path_tracer.h>

#include <packed_hit.cuh>

// Threads per block of every stage (not tuned: every measurement in the handouts uses 128).
// Each kernel's grid is as many blocks as fit on the GPU at once (wavefront_renderer.cuh),
// and its threads stride over their queue. It also sizes the shared memory in which a push
// stages a block's records (path_pool_aos.cuh).
constexpr int kStageThreads = 128;

// A path on its way to its next interaction; `slot` says which (pixel, sample) it is.
struct QueuedPath {
    Ray ray;
    Vec3 throughput;
    int slot;
};

// A light sample's shadow ray, and the slot whose radiance it adds to when nothing blocks it.
struct QueuedShadowRay {
    ShadowRay shadow;
    int slot;
};

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
    // `count` arrays of T one after another, each on a 256-byte boundary: returns the first
    // and sets `stride` to the elements from the start of one to the start of the next.
    template <class T>
    T* take_arrays(int count, int& stride) {
        static_assert(256 % sizeof(T) == 0, "arrays on 256-byte boundaries");
        const size_t array_bytes = (sizeof(T) * static_cast<size_t>(slots_) + 255) / 256 * 256;
        offset_ = (offset_ + 255) / 256 * 256;
        T* first = base_ ? reinterpret_cast<T*>(base_ + offset_) : nullptr;
        offset_ += array_bytes * static_cast<size_t>(count);
        stride = static_cast<int>(array_bytes / sizeof(T));
        return first;
    }
    size_t bytes() const { return offset_; }

private:
    char* base_;
    int slots_;
    size_t offset_ = 0;
};

template <class Layout>
struct PathPool {
    typename Layout::Paths paths[2];  // the active queues of even and odd bounces
    typename Layout::ShadowRays shadow_rays;
    typename Layout::Radiance radiance;

    static PathPool carve(void* memory, int slots) {
        ArrayCarver c(memory, slots);
        return laid_out(c);
    }
    static size_t bytes_for(int slots) {
        ArrayCarver c(nullptr, slots);
        laid_out(c);
        return c.bytes();
    }

private:
    static PathPool laid_out(ArrayCarver& c) {
        PathPool p;
        p.paths[0].carve(c);
        p.paths[1].carve(c);
        p.shadow_rays.carve(c);
        p.radiance.carve(c);
        return p;
    }
};
