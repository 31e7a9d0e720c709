// Lab 06: your copy, yours to edit. Every place to fill in is marked TODO(lab06).
// A queue of path ids: the slots of the path pool that a stage must work on. A stage's
// kernel pops its input queue (each thread takes ids from it) and pushes the ids of the paths
// that need the next stage onto that stage's queue. Many threads push at once, so a push
// reserves its place with an atomic add on the queue's size; the ids land in whatever order
// the atomics happen to run, which is why nothing in the renderer depends on that order
// (wave.cuh).
#pragma once

#include <cooperative_groups.h>

struct PathQueue {
    int* items;  // the ids, items[0 .. *size)
    int* size;   // how many ids the queue holds: one counter in device memory
};

// Appends `id`: one atomic add for all the threads of a warp that push together
// ("warp-aggregated"). The pushing threads find each other (coalesced_threads), the first
// of them reserves that many places at once, and each takes its own place by its rank among
// them. A plain atomicAdd per thread is correct too; this turns up to 32 atomics on the same
// counter into one (push_each_atomic below; lab06-bench measures both).
__device__ inline void push(const PathQueue& queue, int id) {
    // TODO(lab06): reserve a place with an atomic add on *queue.size (one per warp: the
    // threads pushing together are cooperative_groups::coalesced_threads()), then store id
    // there. Until then: a plain read and write of the size, which loses an id whenever
    // two threads push at once. A warp's threads push together and all read the same size,
    // so nearly every path is lost (a race): the image comes out black, or nearly.
    const int place = *queue.size;
    *queue.size = place + 1;
    queue.items[place] = id;
}

// The same push with one atomic per thread: what push is measured against.
__device__ inline void push_each_atomic(const PathQueue& queue, int id) {
    queue.items[atomicAdd(queue.size, 1)] = id;
}

// Pops the queue: calls work(id) for every id in it, the ids shared among all the threads
// of the grid (thread t takes items t, t + threads, t + 2 threads, ...). The grid is sized to
// fill the GPU once, not to the queue, whose size only the GPU knows: the host launches
// every stage of a wave without waiting to read a size back. Each thread reads its next id
// before working on the current one: the stages wait on memory, not on arithmetic, and
// the id's load then overlaps the work instead of adding a round trip to every item.
template <class Work>
__device__ inline void for_each_queued(const PathQueue& queue, Work&& work) {
    const int size = *queue.size;
    const int threads = static_cast<int>(gridDim.x * blockDim.x);
    int k = static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x);
    int id = k < size ? queue.items[k] : 0;
    for (; k < size; k += threads) {
        const int next = k + threads < size ? queue.items[k + threads] : 0;
        work(id);
        id = next;
    }
}
