// The scene as one block of 16-byte words (the rectangles' slabs, the materials, then each
// primitive kind's array in the order of AllPrimitives, primitive_kinds.h), so that a single
// copy puts it in any of the GPU's memories, and the SceneView the shared core reads from it
// wherever it lies: global memory, the constant bank or a block's shared memory.
#pragma once

#include <cuda_runtime.h>

#include <cstring>
#include <vector>

#include <rect_slabs.cuh>
#include <scene_view.h>

// Where the kernel reads the scene from. Every thread of a warp reads the same primitive at
// the same time (the core's loops run over all primitives in order), so each memory serves
// a warp's read as one broadcast; they differ in latency and in how much scene fits.
enum class SceneMemory {
    Global,    // device memory through the L1 cache: any size
    Constant,  // the constant bank and its cache: up to kConstantPoolBytes
    Shared,    // copied into each block's shared memory at its start: up to the block limit
};

// Where one kind's array lies in the pool and how many primitives it holds.
template <class K>
struct KindPlace {
    int count = 0;
    int word = 0;  // its first 16-byte word
};

// Where each array starts in the pool, in 16-byte words, and the scene's small fields. The
// rectangles' slabs (rect_slabs.cuh) come first, at word 0, one RectSlab per AxisRect of the
// scene in the same order: a kernel that reads the pool from the constant bank then knows
// each slab's address at compile time.
struct SceneLayout {
    int num_materials = 0;
    int material_word = 0;  // after the slabs; then each kind of AllPrimitives in the list's order
    PerKind<KindPlace, AllPrimitives> primitives;
    int words = 0;  // the whole pool
    PointLight light{};
    bool has_light = false;
    Vec3 background{0.0f};

    template <class K>
    __host__ __device__ KindPlace<K>& of() {
        return primitives.of<K>();
    }
    template <class K>
    __host__ __device__ const KindPlace<K>& of() const {
        return primitives.of<K>();
    }

    size_t bytes() const { return static_cast<size_t>(words) * sizeof(float4); }

    // The core's view of a pool that starts at `pool`, in whichever memory that is. Inlined
    // into the kernel, the compiler sees where the pointers came from and uses that memory's
    // own load instructions (LDC for constant, LDS for shared).
    __host__ __device__ SceneView view(const float4* pool) const {
        SceneView v{{},
                    reinterpret_cast<const Material*>(pool + material_word),
                    num_materials,
                    light,
                    has_light,
                    background};
        for_each_kind(AllPrimitives{}, [&](auto kind) {
            using K = typename decltype(kind)::type;
            v.primitives.of<K>() = {reinterpret_cast<const K*>(pool + of<K>().word), of<K>().count};
        });
        return v;
    }
};

inline int words_for(size_t bytes) { return static_cast<int>((bytes + 15) / 16); }

// The layout of a scene's pool (`scene`: its arrays on the host).
inline SceneLayout layout_of(const SceneView& scene) {
    SceneLayout l;
    l.num_materials = scene.num_materials;
    l.material_word = words_for(scene.of<AxisRect>().count * sizeof(RectSlab));
    int word = l.material_word + words_for(scene.num_materials * sizeof(Material));
    for_each_kind(AllPrimitives{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        l.of<K>() = {scene.of<K>().count, word};
        word += words_for(scene.of<K>().count * sizeof(K));
    });
    l.words = word;
    l.light = scene.light;
    l.has_light = scene.has_light;
    l.background = scene.background;
    return l;
}

// The pool's bytes on the host, ready to copy.
inline std::vector<float4> pack(const SceneView& scene, const SceneLayout& l) {
    std::vector<float4> pool(l.words > 0 ? l.words : 1, float4{0, 0, 0, 0});
    const auto put = [&](int word, const void* data, size_t bytes) {
        if (bytes) std::memcpy(pool.data() + word, data, bytes);
    };
    const KindSpan<AxisRect> rects = scene.of<AxisRect>();
    for (int i = 0; i < rects.count; ++i) {
        const RectSlab slab = rect_slab(rects[i]);
        put(i * kWordsPerSlab, &slab, sizeof slab);
    }
    put(l.material_word, scene.materials, scene.num_materials * sizeof(Material));
    for_each_kind(AllPrimitives{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        put(l.of<K>().word, scene.of<K>().items, scene.of<K>().count * sizeof(K));
    });
    return pool;
}

// Where a renderer puts the scene: each block's shared memory when it is small (the Cornell
// box's 5 rectangles, sphere and 4 materials take under 300 bytes; shared memory measured faster
// than the constant bank and global memory there, handouts/05-cuda-mega.md), else global
// memory, through the L1 cache: every block copies the whole scene first, which for a large
// scene would cost more than it saves.
constexpr size_t kSharedSceneBytes = 16 * 1024;

inline SceneMemory choose_scene_memory(const SceneLayout& layout) {
    return layout.bytes() <= kSharedSceneBytes ? SceneMemory::Shared : SceneMemory::Global;
}

// The constant bank's copy: 48 KiB of the 64 KiB a program may use (about 850 triangles),
// leaving room for the constants the compiler places there itself.
constexpr size_t kConstantPoolBytes = 48 * 1024;
__constant__ float4 constant_pool[kConstantPoolBytes / sizeof(float4)];

inline bool fits_constant(const SceneLayout& l) { return l.bytes() <= kConstantPoolBytes; }

// The scene as one block of the kernel sees it, given the pool in global memory. For
// Shared, the block's threads first copy the pool into `shared` together; every thread of
// the block must call this, before any of them returns.
template <SceneMemory kMemory>
__device__ inline SceneView scene_in(const SceneLayout& layout, const float4* global_pool,
                                     float4* shared) {
    if constexpr (kMemory == SceneMemory::Constant) {
        return layout.view(constant_pool);
    } else if constexpr (kMemory == SceneMemory::Shared) {
        for (int i = threadIdx.x; i < layout.words; i += blockDim.x) shared[i] = global_pool[i];
        __syncthreads();
        return layout.view(shared);
    } else {
        return layout.view(global_pool);
    }
}

// The rectangles' slabs of the pool of scene_in<kMemory>: at word 0 of the same memory. From
// the constant bank the compiler knows each slab's address, not only the pool's.
template <SceneMemory kMemory>
__device__ inline const RectSlab* slabs_in(const float4* global_pool, const float4* shared) {
    if constexpr (kMemory == SceneMemory::Constant) {
        return reinterpret_cast<const RectSlab*>(constant_pool);
    } else if constexpr (kMemory == SceneMemory::Shared) {
        return reinterpret_cast<const RectSlab*>(shared);
    } else {
        return reinterpret_cast<const RectSlab*>(global_pool);
    }
}
