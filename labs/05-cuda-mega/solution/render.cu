// Lab 05: the path tracer on a GPU as one "megakernel": each CUDA thread runs whole camera
// paths through the shared core (common/core), which is written once for host and device.
//
// This file is the host side: open the GPU, put the scene in device memory, launch the
// kernel over the image (in bands when the image is larger than the GPU's free memory),
// copy the pixels back. RenderStats::seconds is the kernels' time on the GPU, measured with
// CUDA events; it leaves out context creation, module loading and every copy, which the
// handout measures separately.
#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

#include <lab.h>

#include <cuda_check.h>
#include <device_array.h>
#include <gpu_device.h>
#include <gpu_timer.h>
#include <megakernel.cuh>
#include <scene_pool.cuh>

const char* const kLabName = "05-cuda-mega";

// The launch shape, each choice measured on an H200 with lab05-bench (baseline kernel times,
// best of 5, in handouts/05-cuda-mega.md): 32 threads share a pixel's samples (a grid of
// millions of threads, so the last wave of blocks is a small part of the work, while a
// pixel's threads still fit in one warp for the shuffles; section 3's table of threads per
// pixel); blocks of 64 threads and at most 72 registers a thread (a few bytes of spills at
// 44% occupancy beat both fewer spills and more occupancy; section 5's tables); by bounces
// with path regeneration; only the material kinds the scene uses (no glass code, fewer
// spills; section 6).
constexpr int kThreadsPerPixel = 32;
constexpr int kBlockThreads = 64;
constexpr bool kRegenerate = true;
constexpr int kMaxRegisters = 72;

// One kernel per place for the scene (choose_scene_memory, scene_pool.cuh) and per set of
// material kinds (material_set.h): a scene without mirrors or glass gets a kernel without
// their code.
template <SceneMemory kMemory, class Materials>
constexpr auto kernel_for =
    render_kernel<kThreadsPerPixel, kMemory, kBlockThreads, kRegenerate, kMaxRegisters, Materials>;

// The most bytes of device memory the image's pixels may take at once; more rows than that
// are rendered in several bands. RT_LAB05_BAND_BYTES lowers it (the tests force bands so).
static size_t band_budget_bytes() {
    size_t free_bytes = 0, total_bytes = 0;
    check(cudaMemGetInfo(&free_bytes, &total_bytes), "reading the GPU's free memory");
    size_t budget = free_bytes / 2;  // room for the driver, the stack frames, other users
    if (const char* limit = std::getenv("RT_LAB05_BAND_BYTES")) {
        budget = std::min(budget, static_cast<size_t>(std::strtoull(limit, nullptr, 10)));
    }
    return budget;
}

// Makes the kernel ready before anything is timed: loads its module (CUDA loads modules
// lazily, at the first launch, which would otherwise land inside the timed region) and
// allows the dynamic shared memory it needs.
template <SceneMemory kMemory, class Materials>
static void prepare_kernel(size_t shared_bytes) {
    cudaFuncAttributes attributes{};
    check(cudaFuncGetAttributes(&attributes, kernel_for<kMemory, Materials>),
          "loading the render kernel");
    if (shared_bytes > 0) {
        check(cudaFuncSetAttribute(kernel_for<kMemory, Materials>,
                                   cudaFuncAttributeMaxDynamicSharedMemorySize,
                                   static_cast<int>(shared_bytes)),
              "giving the kernel the shared memory for the scene");
    }
}

// One band: launch the kernel over its pixels and return its GPU time in seconds.
template <SceneMemory kMemory, class Materials>
static double render_band(const KernelArgs& args, size_t shared_bytes) {
    GpuTimer timer;
    // BEGIN SOLUTION
    const long long threads =
        static_cast<long long>(args.rows) * args.settings.width * kThreadsPerPixel;
    const unsigned blocks = static_cast<unsigned>((threads + kBlockThreads - 1) / kBlockThreads);
    timer.start();
    kernel_for<kMemory, Materials><<<blocks, kBlockThreads, shared_bytes>>>(args);
    timer.stop();
    // SKELETON
    //> // TODO(lab05): launch enough blocks of kBlockThreads threads for your kernel's
    //> // mapping: kThreadsPerPixel threads for every pixel of the band (rows x width).
    //> // Until then: one thread per row, as the placeholder kernel expects.
    //> const unsigned blocks = static_cast<unsigned>((args.rows + kBlockThreads - 1) / kBlockThreads);
    //> timer.start();
    //> kernel_for<kMemory, Materials><<<blocks, kBlockThreads, shared_bytes>>>(args);
    //> timer.stop();
    // END SOLUTION
    check_launch("running the render kernel");
    return timer.seconds();
}

template <SceneMemory kMemory, class Materials>
static double render_bands(KernelArgs args, size_t shared_bytes, Image& image, Progress& progress) {
    prepare_kernel<kMemory, Materials>(shared_bytes);
    const int width = args.settings.width, height = args.settings.height;
    const size_t row_bytes = static_cast<size_t>(width) * sizeof(Vec3);
    const size_t budget = band_budget_bytes();
    if (budget < row_bytes) {
        throw GpuError("GPU: not enough free device memory for even one row of the image (" +
                       std::to_string(row_bytes) + " bytes needed, " + std::to_string(budget) +
                       " available)");
    }
    const int band_rows = static_cast<int>(std::min<size_t>(height, budget / row_bytes));
    DeviceArray<Vec3> band(static_cast<size_t>(band_rows) * width, "allocating the image band");
    args.pixels = band.data();
    double seconds = 0;
    for (int first = 0; first < height; first += band_rows) {
        args.first_row = first;
        args.rows = std::min(band_rows, height - first);
        seconds += render_band<kMemory, Materials>(args, shared_bytes);
        check(cudaMemcpy(&image.at(0, first), band.data(), args.rows * row_bytes,
                         cudaMemcpyDeviceToHost),
              "copying the pixels back from the GPU");
        progress.rows_done(args.rows);
    }
    return seconds;
}

RenderStats render(const RenderJob& job, Image& image) {
    const cudaDeviceProp prop = open_device();
    SceneLayout layout = layout_of(job.scene);
    const std::vector<float4> host_pool = pack(job.scene, layout);
    const SceneMemory memory = choose_scene_memory(layout);

    // The scene in global memory: what the kernel reads, or the source of each block's copy.
    DeviceArray<float4> pool(host_pool.size(), "allocating the scene on the GPU");
    // BEGIN SOLUTION
    check(cudaMemcpy(pool.data(), host_pool.data(), pool.bytes(), cudaMemcpyHostToDevice),
          "copying the scene to the GPU");
    // SKELETON
    //> // TODO(lab05): copy the whole pool (host_pool) to the device: cudaMemcpy into
    //> // pool.data(), pool.bytes() bytes, its status passed to check(). Until then: only the
    //> // materials and spheres go up; the triangles are left out.
    //> layout.num_triangles = 0;
    //> check(cudaMemcpy(pool.data(), host_pool.data(), layout.triangle_word * sizeof(float4),
    //>                  cudaMemcpyHostToDevice),
    //>       "copying the scene to the GPU");
    // END SOLUTION

    const KernelArgs args{layout, pool.data(), job.camera, job.settings, 0, 0, nullptr};
    const bool specular = has_specular_material(job.scene.materials, job.scene.num_materials);
    double seconds = 0;
    if (memory == SceneMemory::Shared) {
        const size_t bytes = layout.bytes();
        seconds =
            specular
                ? render_bands<SceneMemory::Shared, AnyMaterial>(args, bytes, image, job.progress)
                : render_bands<SceneMemory::Shared, DiffuseOnly>(args, bytes, image, job.progress);
    } else {
        seconds =
            specular ? render_bands<SceneMemory::Global, AnyMaterial>(args, 0, image, job.progress)
                     : render_bands<SceneMemory::Global, DiffuseOnly>(args, 0, image, job.progress);
    }
    return {seconds, describe(prop), kKernelTimeOnly};
}
