// Lab 06: your copy, yours to edit. Every place to fill in is marked TODO(lab06).
// A queue of work for the next stage: the items themselves (paths, shadow rays), stored in
// a path pool's layout (path_pool.cuh), and a size counter in device memory. A stage's kernel
// pops its input queue (each thread takes places of it) and pushes what the next stage must
// do onto that stage's queue. Many threads push at once, so a push reserves its place with an
// atomic add on the queue's size; the items land in whatever order the atomics happen to run,
// which is why nothing in the renderer depends on that order (wave.cuh).
//
// The items are copied into the queue, not referred to by an id: a queue is dense, so the
// threads of a warp that pop places k, k+1, ..., k+31 read neighbouring memory however many
// paths have ended before (handouts/06-cuda-split.md, section 2).
#pragma once

#include <cooperative_groups.h>

template <class Items>
struct Queue {
    Items items;  // places 0 .. *size - 1 (a layout's Paths or ShadowRays)
    int* size;    // how many items the queue holds: one counter in device memory
};

// Reserves one place on the queue whose counter is `size` for the calling thread and returns
// it: one atomic add for all the threads of a warp that push together ("warp-aggregated").
// The pushing threads find each other (coalesced_threads), the first of them reserves that
// many places at once, and each takes its own place by its rank among them, so a warp's items
// also land side by side. A plain atomicAdd per thread is correct too; this turns up to 32
// atomics on the same counter into one (reserve_each below; lab06-bench measures both).
__device__ inline int reserve(int* size) {
    // TODO(lab06): reserve the place with an atomic add on *size (one per warp: the
    // threads pushing together are cooperative_groups::coalesced_threads()), and return
    // it. Until then: a plain read and write of the size, which gives two threads the same
    // place whenever they push at once. A warp's threads push together and all read the
    // same size, so nearly every path overwrites another (a race): the image comes out
    // black, or nearly.
    const int place = *size;
    *size = place + 1;
    return place;
}

// The same reservation with one atomic per thread: what reserve is measured against.
__device__ inline int reserve_each(int* size) { return atomicAdd(size, 1); }

// Appends `item` (a QueuedPath or a QueuedShadowRay) at a place reserved as kAggregated says.
template <bool kAggregated = true, class Items, class Item>
__device__ inline void push(const Queue<Items>& queue, const Item& item) {
    if constexpr (kAggregated) {
        queue.items.store(reserve(queue.size), item);
    } else {
        queue.items.store(reserve_each(queue.size), item);
    }
}

// Pops the queue: calls work(k) for every place k in it, the places shared among all the
// threads of the grid (thread t takes t, t + threads, t + 2 threads, ...), so that a warp
// works on 32 neighbouring places. The grid is sized to fill the GPU once, not to the queue,
// whose size only the GPU knows: the host launches every stage of a wave without waiting to
// read a size back.
template <class Items, class Work>
__device__ inline void for_each_queued(const Queue<Items>& queue, Work&& work) {
    const int size = *queue.size;
    const int threads = static_cast<int>(gridDim.x * blockDim.x);
    for (int k = static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x); k < size; k += threads) {
        work(k);
    }
}
