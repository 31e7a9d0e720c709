// Lab 05's choice of where the megakernel reads the scene: the constant bank wherever the
// pool fits in it (scene_pool.cuh's constant_pool), else global memory.
//
// Every lane of a warp reads the same primitive at the same time, and the loop bounds and
// pool offsets are kernel parameters, so a warp's lanes read one address: the constant
// bank's broadcast case, one LDC per field from the constant cache. Unlike shared memory it
// needs no copy into every block and no barrier before the first read (the megakernel's
// blocks are small and many: 180,000 of them on the baseline). A scene too large for the
// bank is read from global memory through the L1 cache; shared memory, which holds less
// than the bank, is never the better place for a scene the bank cannot hold. lab05-bench's
// scene-shared and scene-global shapes measure the alternatives on the baseline.
#pragma once

#include <cuda_runtime.h>

#include <vector>

#include <cuda_check.h>
#include <scene_pool.cuh>

inline SceneMemory choose_megakernel_scene_memory(const SceneLayout& layout) {
    return fits_constant(layout) ? SceneMemory::Constant : SceneMemory::Global;
}

// Copies the pool into the constant bank; the caller has checked fits_constant. Synchronous,
// so no kernel launched afterwards can see an older scene.
inline void upload_to_constant(const std::vector<float4>& host_pool, const SceneLayout& layout) {
    if (layout.bytes() == 0) return;
    check(cudaMemcpyToSymbol(constant_pool, host_pool.data(), layout.bytes()),
          "copying the scene to the GPU's constant memory");
}
