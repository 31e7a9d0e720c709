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
//
// How a block reserves its places, reserve, is what lab 06's students write: it has a header
// of its own, queue_reserve.cuh.
#pragma once

#include <cooperative_groups.h>

#include <type_traits>
#include <utility>

#include <queue_reserve.cuh>  // reserve: a block's places with one atomic add

template <class Items>
struct Queue {
    Items items;  // places 0 .. *size - 1 (a layout's Paths or ShadowRays)
    int* size;    // how many items the queue holds: one counter in device memory
};

// How the threads that push onto a queue reserve their places (lab06-bench measures each).
enum class Reserve {
    kPerBlock,   // one atomic add on the counter per block: reserve below
    kPerWarp,    // one per warp: reserve_per_warp
    kPerThread,  // one per thread: reserve_per_thread
};

// The same reservation as reserve (queue_reserve.cuh) with one atomic add per warp: the
// pushing threads of the warp find each other (coalesced_threads), the first reserves for
// all, each takes its place by rank.
__device__ inline int reserve_per_warp(int* size, bool wants) {
    if (!wants) return -1;
    namespace cg = cooperative_groups;
    const cg::coalesced_group pushing = cg::coalesced_threads();
    int first = 0;
    if (pushing.thread_rank() == 0) first = atomicAdd(size, static_cast<int>(pushing.size()));
    return pushing.shfl(first, 0) + static_cast<int>(pushing.thread_rank());
}

// And with one atomic add per thread (the compiler may still combine a warp's additions).
__device__ inline int reserve_per_thread(int* size, bool wants) {
    return wants ? atomicAdd(size, 1) : -1;
}

// Whether a layout's items have store_together(place, wants, item), a store that every thread
// of the block calls at once for the places of one reserve (lab 06's records: through shared
// memory, path_pool_aos.cuh); otherwise each pushing thread stores its own item.
template <class Items, class Item, class = void>
constexpr bool kStoresTogether = false;
template <class Items, class Item>
constexpr bool kStoresTogether<Items, Item,
                               std::void_t<decltype(std::declval<const Items&>().store_together(
                                   0, true, std::declval<const Item&>()))>> = true;

// Pushes `item` (a QueuedPath or a QueuedShadowRay) for each thread that `wants` to; every
// thread of the block calls it together (see reserve).
template <Reserve kHow = Reserve::kPerBlock, bool kTogether = true, class Items, class Item>
__device__ inline void push(const Queue<Items>& queue, bool wants, const Item& item) {
    int place;
    if constexpr (kHow == Reserve::kPerBlock) {
        place = reserve(queue.size, wants);
    } else if constexpr (kHow == Reserve::kPerWarp) {
        place = reserve_per_warp(queue.size, wants);
    } else {
        place = reserve_per_thread(queue.size, wants);
    }
    if constexpr (kHow == Reserve::kPerBlock && kTogether && kStoresTogether<Items, Item>) {
        queue.items.store_together(place, wants, item);
    } else if (wants) {
        queue.items.store(place, item);
    }
}

// Calls work(k, valid) for the places of a queue of `size` places, block by block: block b
// takes places b * blockDim.x ... b * blockDim.x + blockDim.x - 1, and if the grid has fewer
// threads than the queue has places, that plus the grid's threads, and so on. So a warp works
// on 32 neighbouring places, and the loop is the same for every thread of a block, which lets
// work push (a push synchronises the block); valid is false for the threads past the end.
// The host sizes the grid without knowing the queue's size, which only the GPU knows, so
// that it can launch every stage of a wave without waiting: one thread per place the queue
// could hold (wavefront_renderer.cuh), most of which find nothing to do on a short queue.
template <class Work>
__device__ inline void for_each_place(int size, Work&& work) {
    const int threads = static_cast<int>(gridDim.x * blockDim.x);
    for (int first = static_cast<int>(blockIdx.x * blockDim.x); first < size; first += threads) {
        const int k = first + static_cast<int>(threadIdx.x);
        work(k, k < size);
    }
}

// Pops a queue whose kernel pushes nothing: work(k, load(k)) for every place k in it, each
// thread on its own (t, t + threads, t + 2 threads, ...; one turn with the grid the host
// launches). With kPrefetch each thread loads its next item before it works on the current
// one, so that the next item's trip from memory overlaps the current one's work: no faster
// on the H200 (handouts/06-cuda-split.md, section 2), so off by default.
template <bool kPrefetch = false, class Items, class Load, class Work>
__device__ inline void for_each_queued(const Queue<Items>& queue, Load&& load, Work&& work) {
    const int size = *queue.size;
    const int threads = static_cast<int>(gridDim.x * blockDim.x);
    int k = static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x);
    if constexpr (!kPrefetch) {
        for (; k < size; k += threads) work(k, load(k));
    } else {
        if (k >= size) return;
        auto item = load(k);
        for (int next = k + threads; next < size; k = next, next += threads) {
            auto following = load(next);
            work(k, item);
            item = following;
        }
        work(k, item);
    }
}
