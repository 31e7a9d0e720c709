// Lab 06: your copy, yours to edit. Every place to fill in is marked TODO(lab06).
// Lab 06, the part students write: how the threads of a block that push onto a queue
// (path_queue.cuh) reserve their places on it. path_queue.cuh's push calls reserve for every
// thread of the block at once; the two alternatives lab06-bench compares it with, one atomic
// add per warp and one per thread, are path_queue.cuh's (reserve_per_warp, reserve_per_thread).
#pragma once

// Reserves a place on the queue whose counter is `size` for each thread of the block that
// `wants` one, and returns it (-1 for a thread that wants none). Every thread of the block
// calls it together: it synchronises the block. The threads first count themselves in
// shared memory, where atomics are cheap; then one thread reserves that many places with one
// atomic add on the queue's size, and each takes its place by its rank in the count.
//
// Why not one atomic per thread, or per warp: every thread of the GPU pushing onto the same
// queue adds to the same counter, and the L2 performs the additions to one address one after
// another (handouts/06-cuda-split.md, section 2, times them on the H200). A warp that waits for
// its place waits for all the additions queued before its own. The compiler already combines
// a warp's additions to one address; one per block of 128 threads makes 4 times fewer.
__device__ inline int reserve(int* size, bool wants) {
    // TODO(lab06): count the block's threads that want a place (an atomic add on a
    // __shared__ counter gives each its rank), let one thread reserve that many places
    // with one atomicAdd on *size, and give each wanting thread the first place plus its
    // rank; __syncthreads() between the steps. Until then: a plain read and write of the
    // size, which gives many threads the same place when they push at once, so nearly
    // every path overwrites another (a race): the image comes out black, or nearly.
    if (!wants) return -1;
    const int place = *size;
    *size = place + 1;
    return place;
}
