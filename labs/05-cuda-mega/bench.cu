// The measurements behind lab 05's choices (handouts/05-cuda-mega.md): the megakernel in
// several shapes, each timed by CUDA events on the same scene and settings, after a
// warm-up, best and median of --repeat runs. Prints one JSON object, one line per shape,
// ending with lab 05's speed targets (speed_targets.h) and whether this run meets them.
//
//   ./lab05-bench [the shared flags: --scene --width --height --spp --bounces --seed]
//                 [--repeat N] [--only NAME[,NAME...]] [--list]
//
// "reference" is what lab05-ref runs on the Cornell baseline: the small-scene kernel
// (small_scene.cuh) for the box's counts, one sphere and five rectangles, compiled as
// kernel_choice.cuh says (the hit's surface by index, at most 56 registers, 64 in the
// fast-math build), 32 threads per pixel, blocks of 64, whole paths. "kinds-kernel" is what
// lab05-ref runs on a scene the small-scene kernels do not hold, and was its reference on the
// baseline before them: render_kernel.cuh's whole paths through the core's path loop, at most
// 56 registers, the scene in the constant bank, the rectangles tested as slabs
// (slab_geometry.cuh), a kernel compiled for the scene's kinds of material (DiffuseOnly) and
// primitive (spheres and axis-aligned rectangles: BoxGeometry), their counts read at run time.
// Each "small-" shape changes one thing of the reference: the surface by selects, the shadow
// ray against every rectangle, the register cap (a shape that would compile to the
// reference's own kernel is left out). Every other shape changes one thing of the kinds kernel:
// the scene's primitives (its rectangles as convex quads, or every quad as two triangles,
// general_geometry.h, each with a kernel for those kinds; "general" is what lab05-ref runs
// with RT_LAB05_GEOMETRY=general), the rectangles' test (the core's exact one), the kinds
// compiled in, where the scene lives, how a thread traces its samples (path regeneration,
// lanes kept together, samples claimed by the warp), the register cap, the work split or the
// block. "plain" is the first kernel anyone writes (one thread per pixel calling the core's
// render_pixel, 16x16 blocks, the scene in global memory, no register cap). The small-scene
// shapes run on a scene of one sphere and five rectangles only. A shape compiled for kinds the
// scene does not fit (DiffuseOnly on a scene with mirrors or glass, BoxGeometry on one with
// triangles) is left out; the first shape run is the image the others are compared with, bit
// for bit where they render the same primitives with the same code. The kinds kernel before
// the slabs (the core's exact rectangle test) is the exact-rects shape; the one before that
// (triangles, branching primitive loops, shared memory, path regeneration, at most 72
// registers) is this file's "reference" at commit df6fc16.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <cli.h>
#include <scene_loader.h>

#include <bench_main.h>
#include <cuda_check.h>
#include <device_array.h>
#include <general_geometry.h>
#include <geometry_set.h>
#include <gpu_device.h>
#include <gpu_timer.h>
#include <kernel_choice.cuh>
#include <megakernel.cuh>
#include <scene_constant.cuh>
#include <scene_pool.cuh>
#include <small_scene.cuh>
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

// Kernels for the scene's walls in one kind of primitive only, besides the sphere.
using SpheresAndQuads = Kinds<Sphere, ConvexQuad>;
using SpheresAndTriangles = Kinds<Sphere, Triangle>;

struct Variant {
    const char* name;  // as in the handout's tables
    const char* change;  // what differs from the reference shape
    int threads_per_pixel;
    SceneMemory memory;
    int block_threads;
    PathLoop loop;  // how a thread traces its samples (megakernel.cuh)
    int max_registers;  // render_kernel's cap (255: none)
    bool slab_rects;  // the rectangles as slabs (slab_geometry.cuh), else the core's exact test
    bool diffuse_only;  // compiled for DiffuseOnly (material_set.h), else for AnyMaterial
    GeometryForm form;  // the scene's primitives as loaded, or re-expressed (general_geometry.h)
    const char* primitives;  // the primitive kinds compiled in (geometry_set.h)
    bool (*fits)(const GeometryKinds&);  // whether those kinds render the scene in `form`
    const void* kernel;
    void (*launch)(const KernelArgs&, size_t shared_bytes);
    // A small-scene kernel (small_scene.cuh): the scene's counts it is compiled for (-1: not
    // one), and what copies the scene into its part of the constant bank.
    int small_spheres = -1, small_rects = -1;
    void (*prepare)(const SceneView&) = nullptr;
};

template <int kT, SceneMemory kM, int kB, PathLoop kLoop, int kMaxRegisters, class Materials,
          class Primitives, bool kSlabs>
void launch_megakernel(const KernelArgs& args, size_t shared_bytes) {
    const long long threads = static_cast<long long>(args.rows) * args.settings.width * kT;
    const unsigned blocks = static_cast<unsigned>((threads + kB - 1) / kB);
    render_kernel<kT, kM, kB, kLoop, kMaxRegisters, Materials, Primitives, kSlabs>
        <<<blocks, kB, shared_bytes>>>(args);
}

template <int kS, int kR, int kB, int kMaxRegisters, bool kCull, bool kBySelects>
void launch_small(const KernelArgs& args, size_t) {
    const long long threads = static_cast<long long>(args.rows) * args.settings.width * 32;
    const unsigned blocks = static_cast<unsigned>((threads + kB - 1) / kB);
    small_scene_kernel<kS, kR, 32, kB, kMaxRegisters, kCull, kBySelects><<<blocks, kB>>>(args);
}

void launch_plain(const KernelArgs& args, size_t) {
    const dim3 block(16, 16);
    const dim3 grid((args.settings.width + 15) / 16, (args.settings.height + 15) / 16);
    plain_kernel<<<grid, block>>>(args.layout.view(args.scene_pool), args.camera, args.settings,
                                  args.pixels);
}

template <class Primitives>
bool fits(const GeometryKinds& kinds) {
    return kinds.fits<Primitives>();
}

// One shape: t threads per pixel, scene memory m, blocks of b, path loop, register cap,
// material kinds, primitive kinds, the scene's geometry form, the rectangles as slabs.
#define MEGA_TESTS(name, change, t, m, b, loop, regs, mats, prims, form, slabs)                 \
    Variant {                                                                                   \
        name, change, t, SceneMemory::m, b, PathLoop::loop, regs, slabs,                        \
            std::is_same_v<mats, DiffuseOnly>, GeometryForm::form, #prims, fits<prims>,         \
            reinterpret_cast<const void*>(                                                      \
                render_kernel<t, SceneMemory::m, b, PathLoop::loop, regs, mats, prims, slabs>), \
            launch_megakernel<t, SceneMemory::m, b, PathLoop::loop, regs, mats, prims, slabs>   \
    }
#define MEGA(name, change, t, m, b, loop, regs, mats, prims, form) \
    MEGA_TESTS(name, change, t, m, b, loop, regs, mats, prims, form, true)
// The reference's shape with one change.
#define SHAPE(name, change, t, m, b, loop, regs) \
    MEGA(name, change, t, m, b, loop, regs, DiffuseOnly, BoxGeometry, AsLoaded)

// A small-scene kernel for the Cornell box's counts (one sphere, five rectangles), 32 threads a
// pixel in blocks of 64: a register cap, the shadow ray's rectangles culled or not, the hit's
// surface by selects or by index.
#define SMALL(name, change, regs, cull, selects)                                                  \
    Variant {                                                                                     \
        name, change, 32, SceneMemory::Constant, 64, PathLoop::WholePaths, regs, true, true,      \
            GeometryForm::AsLoaded, "BoxGeometry", fits<BoxGeometry>,                             \
            reinterpret_cast<const void*>(small_scene_kernel<1, 5, 32, 64, regs, cull, selects>), \
            launch_small<1, 5, 64, regs, cull, selects>, 1, 5, upload_small_scene<1, 5>           \
    }

static const std::vector<Variant>& variants() {
    static const std::vector<Variant> all = {
        // The first of these three that the scene fits is the image the others are compared to.
        SMALL("reference",
              "none: the small-scene kernel for the scene's counts (lab05-ref on a small "
              "diffuse scene of spheres and rectangles)",
              kSmallSceneMaxRegisters, true, kSmallSceneBySelects),
        SHAPE("kinds-kernel",
              "the kernel for the scene's kinds, its counts read at run time (lab05-ref on "
              "any other scene; the reference before the small-scene kernel)",
              32, Constant, 64, WholePaths, 56),
        MEGA("all-materials",
             "compiled for every material and primitive kind (lab05-ref on a "
             "scene with mirrors, glass or triangles)",
             32, Constant, 64, WholePaths, 56, AnyMaterial, AnyGeometry, AsLoaded),
        // The primitives: the same walls as other kinds, each with a kernel for its kinds.
        MEGA("general",
             "walls as convex quads, kernel for every kind but rectangles "
             "(lab05-ref with RT_LAB05_GEOMETRY=general)",
             32, Constant, 64, WholePaths, 56, DiffuseOnly, GeneralGeometry, Quads),
        MEGA("quads", "walls as convex quads, kernel for spheres and quads", 32, Constant, 64,
             WholePaths, 56, DiffuseOnly, SpheresAndQuads, Quads),
        MEGA("triangles", "walls as two triangles each, kernel for spheres and triangles", 32,
             Constant, 64, WholePaths, 56, DiffuseOnly, SpheresAndTriangles, Triangles),
        MEGA("any-geometry", "compiled for every primitive kind", 32, Constant, 64, WholePaths, 56,
             DiffuseOnly, AnyGeometry, AsLoaded),
        // The rectangles' test.
        MEGA_TESTS("exact-rects",
                   "the rectangles by the core's exact test (axis_rect.h), not as slabs", 32,
                   Constant, 64, WholePaths, 56, DiffuseOnly, BoxGeometry, AsLoaded, false),
        // Where the scene lives.
        SHAPE("scene-shared", "scene in shared memory", 32, Shared, 64, WholePaths, 56),
        SHAPE("scene-global", "scene in global memory", 32, Global, 64, WholePaths, 56),
        MEGA("triangles-shared", "walls as two triangles each, scene in shared memory", 32, Shared,
             64, WholePaths, 56, DiffuseOnly, SpheresAndTriangles, Triangles),
        // How a thread traces its samples, and how many registers it may use.
        SHAPE("regenerate", "path regeneration (trace_samples_regenerating)", 32, Constant, 64,
              Regenerate, 56),
        SHAPE("together", "the warp's lanes kept together (trace_samples_together)", 32, Constant,
              64, Together, 56),
        SHAPE("claimed", "samples claimed by the warp's lanes (trace_samples_claimed)", 32,
              Constant, 64, Claimed, 56),
        SHAPE("claimed-regs-64", "samples claimed by the warp's lanes, at most 64 registers", 32,
              Constant, 64, Claimed, 64),
        // The small-scene kernel (small_scene.cuh), one change each.
        SMALL("small-selects", "small, the hit's surface chosen by selects as the loop finds it",
              kSmallSceneMaxRegisters, true, true),
        SMALL("small-no-cull", "small, the shadow ray against every rectangle",
              kSmallSceneMaxRegisters, false, kSmallSceneBySelects),
        SMALL("small-regs-56", "small, at most 56 registers", 56, true, kSmallSceneBySelects),
        SMALL("small-regs-64", "small, at most 64 registers", 64, true, kSmallSceneBySelects),
        SMALL("small-no-register-cap", "small, registers left to the compiler", 255, true,
              kSmallSceneBySelects),
        SHAPE("no-register-cap", "registers left to the compiler", 32, Constant, 64, WholePaths,
              255),
        SHAPE("regs-64", "at most 64 registers", 32, Constant, 64, WholePaths, 64),
        SHAPE("regs-48", "at most 48 registers", 32, Constant, 64, WholePaths, 48),
        SHAPE("split-16", "16 threads per pixel", 16, Constant, 64, WholePaths, 56),
        SHAPE("split-1", "1 thread per pixel", 1, Constant, 64, WholePaths, 56),
        SHAPE("block-32", "blocks of 32", 32, Constant, 32, WholePaths, 56),
        SHAPE("block-128", "blocks of 128", 32, Constant, 128, WholePaths, 56),
        {"plain", "render_pixel per pixel, 16x16 blocks, global memory, every kind", 1,
         SceneMemory::Global, 256, PathLoop::WholePaths, 255, false, false, GeometryForm::AsLoaded,
         "AnyGeometry", fits<AnyGeometry>, reinterpret_cast<const void*>(plain_kernel),
         launch_plain},
    };
    // A shape whose kernel is the reference's (the small-scene shapes at the build's own
    // cap or form) would only time it twice.
    static const std::vector<Variant> distinct = [] {
        std::vector<Variant> out;
        for (const Variant& v : all)
            if (out.empty() || v.kernel != all.front().kernel) out.push_back(v);
        return out;
    }();
    return distinct;
}

static const char* path_loop_name(PathLoop loop) {
    return loop == PathLoop::Together     ? "together"
           : loop == PathLoop::Regenerate ? "regenerate"
           : loop == PathLoop::Claimed    ? "claimed"
                                          : "whole paths";
}

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

// The mean of every channel of every pixel: renders of the same surfaces by other primitive
// tests differ pixel by pixel where a ray meets an edge, but not in their mean.
static double image_mean(const std::vector<Vec3>& image) {
    double sum = 0;
    for (const Vec3& p : image) sum += double(p.x) + p.y + p.z;
    return image.empty() ? 0.0 : sum / (3.0 * image.size());
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
    // The scene in each geometry form a shape may ask for (general_geometry.h), each with its
    // pool on the host and in global memory; a shape in the constant bank gets its form's
    // pool copied there before it runs.
    struct Form {
        GeometryForm form;
        const char* name;
        SceneInForm scene;
        SceneLayout layout;
        std::vector<float4> host_pool;
        Form(const SceneView& view, GeometryForm f, const char* n)
            : form(f),
              name(n),
              scene(view, f),
              layout(layout_of(scene.view)),
              host_pool(pack(scene.view, layout)) {}
    };
    const Form forms[] = {{scene.view(), GeometryForm::AsLoaded, "as loaded"},
                          {scene.view(), GeometryForm::Quads, "rectangles as quads"},
                          {scene.view(), GeometryForm::Triangles, "quads as triangles"}};
    const auto form_of = [&](GeometryForm f) -> const Form& {
        for (const Form& form : forms)
            if (form.form == f) return form;
        return forms[0];
    };
    for (const Form& form : forms) {
        if (!fits_constant(form.layout))
            throw InputError("lab05-bench: the scene (" + std::string(form.name) +
                             ") does not fit in the constant bank (" +
                             std::to_string(form.layout.bytes()) + " bytes, at most " +
                             std::to_string(kConstantPoolBytes) + ")");
    }

    auto t0 = now();
    const cudaDeviceProp prop = open_device();
    const double context_ms = ms_since(t0);

    std::vector<DeviceArray<float4>> pools;
    pools.reserve(std::size(forms));
    double scene_upload_ms = 0;
    for (const Form& form : forms) {
        t0 = now();
        pools.emplace_back(form.host_pool.size(), "allocating the scene on the GPU");
        check(cudaMemcpy(pools.back().data(), form.host_pool.data(), pools.back().bytes(),
                         cudaMemcpyHostToDevice),
              "copying the scene to the GPU");
        if (form.form == GeometryForm::AsLoaded) scene_upload_ms = ms_since(t0);
    }
    const Form* in_constant_bank = nullptr;  // the form whose pool the bank holds
    const size_t n = static_cast<size_t>(settings.width) * settings.height;
    t0 = now();
    DeviceArray<Vec3> pixels(n, "allocating the image");
    const double image_alloc_ms = ms_since(t0);
    const Camera camera = scene.camera.for_image(settings.width, settings.height);
    const double paths = double(n) * settings.spp;

    // The image the others are compared with: the first shape the scene fits.
    const bool specular = has_specular_material(scene.view().materials, scene.view().num_materials);
    const auto runs_on_scene = [&](const Variant& v) {
        const SceneView view = form_of(v.form).scene.view;
        if (v.small_spheres >= 0 && (view.of<Sphere>().count != v.small_spheres ||
                                     view.of<AxisRect>().count != v.small_rects))
            return false;
        return !(v.diffuse_only && specular) && v.fits(geometry_kinds(view));
    };
    const char* image_reference = nullptr;
    for (const Variant& v : variants()) {
        if (runs_on_scene(v)) {
            image_reference = v.name;
            break;
        }
    }

    std::vector<Vec3> reference_image;
    double reference_mean = 0;
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
    for (const Variant& v : variants()) {
        if (!runs_on_scene(v)) continue;
        if (!wanted(only, v.name) && std::strcmp(v.name, image_reference) != 0) continue;
        const Form& form = form_of(v.form);
        const DeviceArray<float4>& pool = pools[&form - forms];
        if (v.memory == SceneMemory::Constant && in_constant_bank != &form) {
            upload_to_constant(form.host_pool, form.layout);
            in_constant_bank = &form;
        }
        if (v.prepare) v.prepare(form.scene.view);
        const KernelArgs args{form.layout, pool.data(),     camera,       settings,
                              0,           settings.height, pixels.data()};
        const size_t shared_bytes = v.memory == SceneMemory::Shared ? form.layout.bytes() : 0;
        cudaFuncAttributes attr{};
        t0 = now();
        check(cudaFuncGetAttributes(&attr, v.kernel), "reading a kernel's attributes");
        if (first) first_load_ms = ms_since(t0);  // loads the module (CUDA loads lazily)
        if (shared_bytes > 0) {
            check(cudaFuncSetAttribute(v.kernel, cudaFuncAttributeMaxDynamicSharedMemorySize,
                                       static_cast<int>(shared_bytes)),
                  "giving a kernel the shared memory for the scene");
        }
        int blocks_per_sm = 0;
        check(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&blocks_per_sm, v.kernel,
                                                            v.block_threads, shared_bytes),
              "computing a kernel's occupancy");
        check(cudaMemset(pixels.data(), 0xff, pixels.bytes()), "poisoning the image");  // NaNs
        const Timing t = time_variant(v, args, shared_bytes, repeat);
        t0 = now();
        const std::vector<Vec3> image = download(pixels);
        if (first) download_ms = ms_since(t0);
        if (reference_image.empty()) {
            reference_image = image;
            reference_mean = image_mean(image);
        }
        size_t nonfinite = 0;
        for (const Vec3& p : image)
            nonfinite += !(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
        const bool identical =
            std::memcmp(image.data(), reference_image.data(), pixels.bytes()) == 0;
        const double occupancy =
            double(blocks_per_sm) * v.block_threads / prop.maxThreadsPerMultiProcessor;
        std::printf(
            "%s\n  {\"name\": \"%s\", \"change\": \"%s\", \"threads_per_pixel\": %d, "
            "\"scene_memory\": \"%s\", \"block_threads\": %d, \"path_loop\": \"%s\", "
            "\"max_registers\": %d, \"materials\": \"%s\", \"primitives\": \"%s\", "
            "\"rect_test\": \"%s\", \"geometry\": \"%s\", \"registers\": %d, \"local_bytes\": %zu, "
            "\"blocks_per_sm\": %d, \"occupancy\": %.3f, \"best_ms\": %.3f, "
            "\"median_ms\": %.3f, \"paths_per_second\": %.4g, \"nonfinite_pixels\": %zu, "
            "\"identical_to_reference\": %s, \"max_relative_difference\": %.3g, "
            "\"mean_ratio_to_reference\": %.5f}",
            first ? "" : ",", v.name, v.change, v.threads_per_pixel,
            v.memory == SceneMemory::Global     ? "global"
            : v.memory == SceneMemory::Constant ? "constant"
                                                : "shared",
            v.block_threads, path_loop_name(v.loop), v.max_registers,
            v.diffuse_only ? "diffuse only" : "any", v.primitives, v.slab_rects ? "slabs" : "exact",
            form.name, attr.numRegs, attr.localSizeBytes, blocks_per_sm, occupancy, t.best_ms,
            t.median_ms, paths / (t.best_ms * 1e-3), nonfinite, identical ? "true" : "false",
            max_relative_difference(reference_image, image),
            reference_mean > 0 ? image_mean(image) / reference_mean : 0.0);
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
        targets_json(kLab05Targets, best_of, why_not_judged(prop, options.scene_path, settings),
                     prop.name)
            .c_str());
    return 0;
}

int main(int argc, char** argv) { return bench_main(run, argc, argv); }
