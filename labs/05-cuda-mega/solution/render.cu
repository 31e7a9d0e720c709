// Lab 05: the path tracer on a GPU as one "megakernel": each CUDA thread runs whole camera
// paths through the shared core (common/core), which is written once for host and device.
//
// This file is the host side: open the GPU, put the scene in device memory (and in the
// constant bank when it fits), launch the kernel compiled for the scene's kinds of primitive
// and material over the image (in bands when the image is larger than the GPU's free
// memory), copy the pixels back. RenderStats::seconds is the kernels' time on the GPU, measured with
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
#include <general_geometry.h>
#include <gpu_timer.h>
#include <kernel_choice.cuh>
#include <megakernel.cuh>
#include <scene_constant.cuh>
#include <scene_pool.cuh>

const char* const kLabName = "05-cuda-mega";

// The launch shape, each choice measured with lab05-bench (the shapes and their times are in
// handouts/05-cuda-mega.md): 32 threads share a pixel's samples (a grid of millions of
// threads, so the last wave of blocks is a small part of the work, while a pixel's threads
// still fit in one warp for the shuffles; section 3); blocks of 64 threads (section 5); whole
// paths (section 7: neither path regeneration, keeping a warp's lanes together nor samples
// claimed by the warp paid); at most 56 registers a thread, for more warps to hide the
// latencies with, at the price of a few spilled bytes (section 5); only the kinds of material
// and primitive the scene uses (sections 6 and 7).
constexpr int kThreadsPerPixel = 32;
constexpr int kBlockThreads = 64;
constexpr PathLoop kLoop = PathLoop::WholePaths;
constexpr int kMaxRegisters = 56;

// One kernel per place for the scene (choose_megakernel_scene_memory, scene_constant.cuh),
// per set of material kinds (material_set.h) and per set of primitive kinds (geometry_set.h):
// a scene without mirrors or glass gets a kernel without their code, the Cornell box one
// with the sphere and rectangle tests only (kernel_choice.cuh).
template <class Choice>
constexpr auto kernel_for =
    render_kernel<kThreadsPerPixel, Choice::kMemory, kBlockThreads, kLoop, kMaxRegisters,
                  typename Choice::Materials, typename Choice::Primitives>;
// BEGIN SOLUTION
//! A scene the small-scene kernels hold (is_small_scene): the kernel for its counts, compiled
//! as kernel_choice.cuh says (the surface by index, its own register cap), launched over the
//! same grid (kThreadsPerPixel threads a pixel, blocks of kBlockThreads).
template <int kSpheres, int kRects>
constexpr auto kernel_for<SmallSceneChoice<kSpheres, kRects>> =
    small_scene_kernel<kSpheres, kRects, kThreadsPerPixel, kBlockThreads, kSmallSceneMaxRegisters,
                       true, kSmallSceneBySelects>;
// END SOLUTION

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
template <class Choice>
static void prepare_kernel(size_t shared_bytes) {
    cudaFuncAttributes attributes{};
    check(cudaFuncGetAttributes(&attributes, kernel_for<Choice>), "loading the render kernel");
    if (shared_bytes > 0) {
        check(cudaFuncSetAttribute(kernel_for<Choice>, cudaFuncAttributeMaxDynamicSharedMemorySize,
                                   static_cast<int>(shared_bytes)),
              "giving the kernel the shared memory for the scene");
    }
}

// One band: launch the kernel over its pixels and return its GPU time in seconds.
template <class Choice>
static double render_band(const KernelArgs& args, size_t shared_bytes) {
    GpuTimer timer;
    // BEGIN SOLUTION
    const long long threads =
        static_cast<long long>(args.rows) * args.settings.width * kThreadsPerPixel;
    const unsigned blocks = static_cast<unsigned>((threads + kBlockThreads - 1) / kBlockThreads);
    timer.start();
    kernel_for<Choice><<<blocks, kBlockThreads, shared_bytes>>>(args);
    timer.stop();
    // SKELETON
    //> // TODO(lab05): launch enough blocks of kBlockThreads threads for your kernel's
    //> // mapping: kThreadsPerPixel threads for every pixel of the band (rows x width).
    //> // Until then: one thread per row, as the placeholder kernel expects.
    //> const unsigned blocks = static_cast<unsigned>((args.rows + kBlockThreads - 1) / kBlockThreads);
    //> timer.start();
    //> kernel_for<Choice><<<blocks, kBlockThreads, shared_bytes>>>(args);
    //> timer.stop();
    // END SOLUTION
    check_launch("running the render kernel");
    return timer.seconds();
}

template <class Choice>
static double render_bands(KernelArgs args, size_t shared_bytes, Image& image, Progress& progress) {
    prepare_kernel<Choice>(shared_bytes);
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
        seconds += render_band<Choice>(args, shared_bytes);
        check(cudaMemcpy(&image.at(0, first), band.data(), args.rows * row_bytes,
                         cudaMemcpyDeviceToHost),
              "copying the pixels back from the GPU");
        progress.rows_done(args.rows);
    }
    return seconds;
}

RenderStats render(const RenderJob& job, Image& image) {
    // The scene's own primitives, or with RT_LAB05_GEOMETRY=general its rectangles as the
    // convex quads they also are (general_geometry.h): read before the GPU is opened, so that
    // a bad setting is bad input (status 2) on any machine.
    const GeometryForm form = lab05_geometry_form(std::getenv("RT_LAB05_GEOMETRY"));
    const SceneInForm scene(job.scene, form);
    const cudaDeviceProp prop = open_device();
    SceneLayout layout = layout_of(scene.view);
    const std::vector<float4> host_pool = pack(scene.view, layout);
    const SceneMemory memory = choose_megakernel_scene_memory(layout);

    // The scene in global memory: what the kernel reads when the scene is too large for the
    // constant bank.
    DeviceArray<float4> pool(host_pool.size(), "allocating the scene on the GPU");
    // BEGIN SOLUTION
    check(cudaMemcpy(pool.data(), host_pool.data(), pool.bytes(), cudaMemcpyHostToDevice),
          "copying the scene to the GPU");
    if (memory == SceneMemory::Constant) upload_to_constant(host_pool, layout);
    // SKELETON
    //> // TODO(lab05): copy the whole pool (host_pool) to the device: cudaMemcpy into
    //> // pool.data(), pool.bytes() bytes, its status passed to check(); and when the scene
    //> // lives in the constant bank (memory == SceneMemory::Constant), into the bank too
    //> // (upload_to_constant, scene_constant.cuh). Until then: the kernel is told of the
    //> // materials and spheres only, so the walls are missing from the image.
    //> layout.of<Triangle>().count = layout.of<ConvexQuad>().count = layout.of<AxisRect>().count = 0;
    //> check(cudaMemcpy(pool.data(), host_pool.data(), pool.bytes(), cudaMemcpyHostToDevice),
    //>       "copying the scene to the GPU");
    //> if (memory == SceneMemory::Constant) upload_to_constant(host_pool, layout);
    // END SOLUTION

    const KernelArgs args{layout, pool.data(), job.camera, job.settings, 0, 0, nullptr};
    const bool specular = has_specular_material(scene.view.materials, scene.view.num_materials);
    // BEGIN SOLUTION
    if (is_small_scene(scene.view, specular)) {
        const double seconds = with_small_scene_choice(
            scene.view.of<Sphere>().count, scene.view.of<AxisRect>().count, [&](auto choice) {
                using Choice = decltype(choice);
                upload_small_scene<Choice::kSphereCount, Choice::kRectCount>(scene.view);
                return render_bands<Choice>(args, 0, image, job.progress);
            });
        return {seconds, describe(prop), kKernelTimeOnly};
    }
    // END SOLUTION
    const double seconds =
        with_kernel_choice(memory, specular, geometry_kinds(scene.view), [&](auto choice) {
            using Choice = decltype(choice);
            const size_t shared_bytes = Choice::kMemory == SceneMemory::Shared ? layout.bytes() : 0;
            return render_bands<Choice>(args, shared_bytes, image, job.progress);
        });
    const char* const forced = form == GeometryForm::AsLoaded ? "" : "; general geometry";
    return {seconds, describe(prop) + forced, kKernelTimeOnly};
}
