// The measurements behind lab 05's choices (handouts/05-cuda-mega.md): the megakernel in
// several shapes, each timed by CUDA events on the same scene and settings, after a
// warm-up, best and median of --repeat runs. Prints one JSON object, ending with lab 05's
// speed targets (speed_targets.h) and whether this run meets them.
//
//   ./lab05-bench [the shared flags: --scene --width --height --spp --bounces --seed]
//                 [--repeat N] [--only NAME[,NAME...]] [--list]
//
// The variants: "reference" is what lab05-ref runs on a scene without mirrors or glass: 32
// threads per pixel, path regeneration, scene in shared memory, blocks of 64, at most 72
// registers, compiled for DiffuseOnly (material_set.h); "all-materials" is the same shape
// compiled for every material, what lab05-ref runs on the others; the "diffuse-" variants
// change one choice of the reference. "plain" is the first kernel anyone writes (one thread
// per pixel calling the core's render_pixel, 16x16 blocks, the scene in global memory).
// The grid after it changes one choice at a time from "reference-16", the previous
// reference (16 threads per pixel, at most 64 registers, every material kind), whose
// measurements the handout's older tables quote. The DiffuseOnly variants are left out on a
// scene with mirrors or glass (they would render it wrong); the first variant run is then
// "all-materials". Every image is compared with the first one's.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <cli.h>
#include <scene_loader.h>

#include <bench_main.h>
#include <cuda_check.h>
#include <device_array.h>
#include <gpu_device.h>
#include <gpu_timer.h>
#include <megakernel.cuh>
#include <scene_pool.cuh>
#include <speed_targets.h>

// The first kernel anyone writes: one thread per pixel, the whole pixel in one call.
__global__ void plain_kernel(SceneView scene, Camera camera, RenderSettings settings,
                             Vec3* pixels) {
    const int x = blockIdx.x * blockDim.x + threadIdx.x;
    const int y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= settings.width || y >= settings.height) return;
    pixels[static_cast<size_t>(y) * settings.width + x] =
        render_pixel(scene, camera, settings, x, y);
}

struct Variant {
    const char* name;    // as in the handout's tables
    const char* change;  // what differs from the reference shape
    int threads_per_pixel;
    SceneMemory memory;
    int block_threads;
    bool regenerate;  // by bounces, starting the next sample at once (else trace_path per sample)
    int max_registers;  // render_kernel's cap (255: none)
    bool diffuse_only;  // compiled for DiffuseOnly (material_set.h), else for AnyMaterial
    const void* kernel;
    void (*launch)(const KernelArgs&, size_t shared_bytes);
};

template <int kT, SceneMemory kM, int kB, bool kRegenerate, int kMaxRegisters, class Materials>
void launch_megakernel(const KernelArgs& args, size_t shared_bytes) {
    const long long threads = static_cast<long long>(args.rows) * args.settings.width * kT;
    const unsigned blocks = static_cast<unsigned>((threads + kB - 1) / kB);
    render_kernel<kT, kM, kB, kRegenerate, kMaxRegisters, Materials>
        <<<blocks, kB, shared_bytes>>>(args);
}

void launch_plain(const KernelArgs& args, size_t) {
    const dim3 block(16, 16);
    const dim3 grid((args.settings.width + 15) / 16, (args.settings.height + 15) / 16);
    plain_kernel<<<grid, block>>>(args.layout.view(args.scene_pool), args.camera, args.settings,
                                  args.pixels);
}

#define MEGA_FOR(name, change, t, m, b, regen, regs, mats)                                         \
    Variant {                                                                                      \
        name, change, t, SceneMemory::m, b, regen, regs, std::is_same_v<mats, DiffuseOnly>,        \
            reinterpret_cast<const void*>(render_kernel<t, SceneMemory::m, b, regen, regs, mats>), \
            launch_megakernel<t, SceneMemory::m, b, regen, regs, mats>                             \
    }
#define MEGA(name, change, t, m, b, regen, regs) \
    MEGA_FOR(name, change, t, m, b, regen, regs, AnyMaterial)
#define MEGA_DIFFUSE(name, change, t, m, b, regen, regs) \
    MEGA_FOR(name, change, t, m, b, regen, regs, DiffuseOnly)

static const std::vector<Variant>& variants() {
    static const std::vector<Variant> all = {
        // The first of these two that the scene allows is the image the others are compared to.
        MEGA_DIFFUSE("reference", "none", 32, Shared, 64, true, 72),
        MEGA("all-materials", "compiled for every material kind", 32, Shared, 64, true, 72),
        MEGA_DIFFUSE("diffuse-split-16", "16 threads per pixel", 16, Shared, 64, true, 72),
        MEGA_DIFFUSE("diffuse-regs-64", "at most 64 registers", 32, Shared, 64, true, 64),
        MEGA_DIFFUSE("diffuse-regs-any", "no register cap", 32, Shared, 64, true, 255),
        MEGA_DIFFUSE("diffuse-whole-paths", "trace_path per sample (no regeneration)", 32, Shared,
                     64, false, 72),
        MEGA_DIFFUSE("diffuse-block-32", "blocks of 32", 32, Shared, 32, true, 72),
        MEGA_DIFFUSE("diffuse-block-128", "blocks of 128", 32, Shared, 128, true, 72),
        MEGA_DIFFUSE("diffuse-scene-global", "scene in global memory", 32, Global, 64, true, 72),
        // From here on, compiled for every material kind: one choice changed from reference-16.
        MEGA("reference-16",
             "the previous reference: 16 threads per pixel, at most 64 registers, every material",
             16, Shared, 64, true, 64),
        {"plain", "render_pixel per pixel, 16x16 blocks, global memory", 1, SceneMemory::Global,
         256, false, 255, false, reinterpret_cast<const void*>(plain_kernel), launch_plain},
        MEGA("whole-paths", "trace_path per sample (no regeneration)", 16, Shared, 64, false, 64),
        MEGA("whole-paths-split-1", "trace_path per sample, 1 thread per pixel", 1, Shared, 64,
             false, 64),
        MEGA("split-1", "1 thread per pixel", 1, Shared, 64, true, 64),
        MEGA("split-2", "2 threads per pixel", 2, Shared, 64, true, 64),
        MEGA("split-4", "4 threads per pixel", 4, Shared, 64, true, 64),
        MEGA("split-8", "8 threads per pixel", 8, Shared, 64, true, 64),
        MEGA("split-32", "32 threads per pixel", 32, Shared, 64, true, 64),
        MEGA("scene-global", "scene in global memory", 16, Global, 64, true, 64),
        MEGA("scene-constant", "scene in the constant bank", 16, Constant, 64, true, 64),
        MEGA("whole-paths-global", "trace_path per sample, scene in global memory", 16, Global, 64,
             false, 64),
        MEGA("whole-paths-constant", "trace_path per sample, scene in the constant bank", 16,
             Constant, 64, false, 64),
        MEGA("regs-any", "no register cap", 16, Shared, 64, true, 255),
        MEGA("whole-paths-regs-any", "trace_path per sample, no register cap", 16, Shared, 64,
             false, 255),
        MEGA("global-regs-any", "scene in global memory, no register cap", 16, Global, 64, true,
             255),
        MEGA("constant-regs-any", "scene in the constant bank, no register cap", 16, Constant, 64,
             true, 255),
        MEGA("regs-56", "at most 56 registers", 16, Shared, 64, true, 56),
        MEGA("regs-48", "at most 48 registers", 16, Shared, 64, true, 48),
        MEGA("regs-40", "at most 40 registers", 16, Shared, 64, true, 40),
        MEGA("block-32", "blocks of 32", 16, Shared, 32, true, 64),
        MEGA("block-128", "blocks of 128", 16, Shared, 128, true, 64),
        MEGA("block-256", "blocks of 256", 16, Shared, 256, true, 64),
        MEGA("block-512", "blocks of 512", 16, Shared, 512, true, 64),
    };
    return all;
}

// Lab 05's bar: the reference kernel (what lab05-ref runs on the baseline) on an H200.
constexpr SpeedTarget kLab05Targets[] = {{"reference", 13.0, nullptr}};

struct Timing {
    double best_ms, median_ms;
};

static Timing time_variant(const Variant& v, const KernelArgs& args, size_t shared_bytes,
                           int repeat) {
    GpuTimer timer;
    std::vector<double> ms;
    for (int i = 0; i <= repeat; ++i) {  // run 0 is the warm-up
        timer.start();
        v.launch(args, shared_bytes);
        timer.stop();
        check_launch(v.name);
        if (i > 0) ms.push_back(timer.seconds() * 1e3);
    }
    std::sort(ms.begin(), ms.end());
    const size_t n = ms.size();
    return {ms.front(), n % 2 ? ms[n / 2] : 0.5 * (ms[n / 2 - 1] + ms[n / 2])};
}

static std::vector<Vec3> download(const DeviceArray<Vec3>& pixels) {
    std::vector<Vec3> host(pixels.size());
    check(cudaMemcpy(host.data(), pixels.data(), pixels.bytes(), cudaMemcpyDeviceToHost),
          "copying the pixels back from the GPU");
    return host;
}

// Largest relative difference between two images (relative to max(|a|, 1e-3)).
static double max_relative_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
    double worst = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        const float pa[3] = {a[i].x, a[i].y, a[i].z}, pb[3] = {b[i].x, b[i].y, b[i].z};
        for (int c = 0; c < 3; ++c) {
            const double d =
                std::abs(double(pa[c]) - pb[c]) / std::max(std::abs(double(pa[c])), 1e-3);
            worst = std::max(worst, d);
        }
    }
    return worst;
}

static bool wanted(const std::string& only, const char* name) {
    if (only.empty()) return true;
    const std::string list = "," + only + ",";
    return list.find("," + std::string(name) + ",") != std::string::npos;
}

static int run(int argc, char** argv) {
    int repeat = 5;
    std::string only;
    std::vector<char*> shared_args = {argv[0]};
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--list") {
            for (const Variant& v : variants()) std::printf("%s\t%s\n", v.name, v.change);
            return 0;
        }
        if ((a == "--repeat" || a == "--only") && i + 1 < argc) {
            if (a == "--repeat") repeat = std::max(1, std::atoi(argv[++i]));
            else only = argv[++i];
            continue;
        }
        shared_args.push_back(argv[i]);
    }
    const Options options =
        parse_options(static_cast<int>(shared_args.size()), shared_args.data(), argv[0]);
    const Scene scene = load_scene(options.scene_path);
    const RenderSettings settings = settings_for(scene, options);
    // Host-side costs a process pays besides the kernel (wall clock, milliseconds).
    const auto now = [] { return std::chrono::steady_clock::now(); };
    const auto ms_since = [&](std::chrono::steady_clock::time_point t) {
        return std::chrono::duration<double, std::milli>(now() - t).count();
    };
    auto t0 = now();
    const cudaDeviceProp prop = open_device();
    const double context_ms = ms_since(t0);

    const SceneLayout layout = layout_of(scene.view());
    const std::vector<float4> host_pool = pack(scene.view(), layout);
    t0 = now();
    DeviceArray<float4> pool(host_pool.size(), "allocating the scene on the GPU");
    check(cudaMemcpy(pool.data(), host_pool.data(), pool.bytes(), cudaMemcpyHostToDevice),
          "copying the scene to the GPU");
    const double scene_upload_ms = ms_since(t0);
    if (!fits_constant(layout))
        throw GpuError("the benchmark needs a scene that fits in constant memory");
    check(cudaMemcpyToSymbol(constant_pool, host_pool.data(), layout.bytes()),
          "copying the scene to the GPU's constant memory");
    const size_t n = static_cast<size_t>(settings.width) * settings.height;
    t0 = now();
    DeviceArray<Vec3> pixels(n, "allocating the image");
    const double image_alloc_ms = ms_since(t0);
    const KernelArgs args{
        layout,       pool.data(), scene.camera.for_image(settings.width, settings.height),
        settings,     0,           settings.height,
        pixels.data()};
    const double paths = double(n) * settings.spp;

    std::vector<Vec3> reference_image;
    std::printf(
        "{\"device\": \"%s\", \"scene\": \"%s\", \"width\": %d, \"height\": %d, "
        "\"spp\": %d, \"bounces\": %d, \"seed\": %llu, \"repeat\": %d, "
        "\"timing\": \"CUDA events around each launch, kernel only; best and median of "
        "repeat runs after one warm-up run\", \"variants\": [",
        describe(prop).c_str(), options.scene_path.c_str(), settings.width, settings.height,
        settings.spp, settings.bounces, static_cast<unsigned long long>(settings.seed), repeat);
    bool first = true;
    double first_load_ms = 0, download_ms = 0;
    std::vector<std::pair<std::string, double>> best_ms;  // of each variant run
    const bool specular = has_specular_material(scene.view().materials, scene.view().num_materials);
    const char* const image_reference = specular ? "all-materials" : "reference";
    for (const Variant& v : variants()) {
        if (v.diffuse_only && specular) continue;
        if (!wanted(only, v.name) && std::strcmp(v.name, image_reference) != 0) continue;
        const size_t shared_bytes = v.memory == SceneMemory::Shared ? layout.bytes() : 0;
        cudaFuncAttributes attr{};
        t0 = now();
        check(cudaFuncGetAttributes(&attr, v.kernel), "reading a kernel's attributes");
        if (first) first_load_ms = ms_since(t0);  // loads the module (CUDA loads lazily)
        int blocks_per_sm = 0;
        check(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&blocks_per_sm, v.kernel,
                                                            v.block_threads, shared_bytes),
              "computing a kernel's occupancy");
        check(cudaMemset(pixels.data(), 0xff, pixels.bytes()), "poisoning the image");  // NaNs
        const Timing t = time_variant(v, args, shared_bytes, repeat);
        t0 = now();
        const std::vector<Vec3> image = download(pixels);
        if (first) download_ms = ms_since(t0);
        if (reference_image.empty()) reference_image = image;
        size_t nonfinite = 0;
        for (const Vec3& p : image)
            nonfinite += !(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
        const bool identical =
            std::memcmp(image.data(), reference_image.data(), pixels.bytes()) == 0;
        const double occupancy =
            double(blocks_per_sm) * v.block_threads / prop.maxThreadsPerMultiProcessor;
        std::printf(
            "%s\n  {\"name\": \"%s\", \"change\": \"%s\", \"threads_per_pixel\": %d, "
            "\"scene_memory\": \"%s\", \"block_threads\": %d, \"regenerate\": %s, \"max_registers\": %d, "
            "\"materials\": \"%s\", "
            "\"registers\": %d, \"local_bytes\": %zu, \"blocks_per_sm\": %d, "
            "\"occupancy\": %.3f, \"best_ms\": %.3f, \"median_ms\": %.3f, "
            "\"paths_per_second\": %.4g, \"nonfinite_pixels\": %zu, "
            "\"identical_to_reference\": %s, \"max_relative_difference\": %.3g}",
            first ? "" : ",", v.name, v.change, v.threads_per_pixel,
            v.memory == SceneMemory::Global     ? "global"
            : v.memory == SceneMemory::Constant ? "constant"
                                                : "shared",
            v.block_threads, v.regenerate ? "true" : "false", v.max_registers,
            v.diffuse_only ? "diffuse only" : "any", attr.numRegs, attr.localSizeBytes,
            blocks_per_sm, occupancy, t.best_ms, t.median_ms, paths / (t.best_ms * 1e-3), nonfinite,
            identical ? "true" : "false", max_relative_difference(reference_image, image));
        std::fflush(stdout);
        best_ms.emplace_back(v.name, t.best_ms);
        first = false;
    }
    const auto best_of = [&](const char* name) {
        for (const auto& [n, ms] : best_ms)
            if (n == name) return ms;
        return -1.0;
    };
    std::printf(
        "\n], \"host_ms\": {\"context_creation\": %.2f, \"module_load\": %.2f, "
        "\"scene_upload\": %.3f, \"image_allocation\": %.3f, \"image_download\": %.3f}, "
        "\"targets\": %s}\n",
        context_ms, first_load_ms, scene_upload_ms, image_alloc_ms, download_ms,
        targets_json(kLab05Targets, best_of, why_not_judged(prop, options.scene_path, settings))
            .c_str());
    return 0;
}

int main(int argc, char** argv) { return bench_main(run, argc, argv); }
