// The host side of the wavefront renderer, for any path-pool layout: plan the waves, put the
// scene, the pool and the queues in device memory, run each wave's stages (run_wave, the
// stage loop in stage_loop.cuh) and bring each band of finished pixels back.
//
// The image is rendered in bands of rows; a band's samples in waves of `samples` samples of
// every pixel of the band, one pool slot per path, at most max_wave_paths() paths a wave.
// The host launches every stage of a wave without waiting: kernels read their queue's size
// on the GPU (path_queue.cuh), so the GPU never idles for a round trip to the host.
// RenderStats::seconds is the GPU time of all the stages by CUDA events, band by band
// (context creation, module loading and the copies of the scene and pixels left out).
#pragma once

#include <algorithm>
#include <array>
#include <cstdlib>
#include <string>
#include <type_traits>
#include <vector>

#include <image.h>
#include <lab.h>

#include <cuda_check.h>
#include <device_array.h>
#include <gpu_device.h>
#include <gpu_timer.h>
#include <layout_probe.cuh>
#include <stage_loop.cuh>
#include <wavefront_kernels.cuh>

// The stages, for the per-kernel tables.
enum Stage { kGenerate, kClosestHit, kShade, kShadow, kAccumulate, kStageCount };
inline const char* stage_name(int stage) {
    static const char* const names[] = {"generate_camera_paths", "find_closest_hits", "shade_hits",
                                        "trace_shadow_rays", "accumulate_samples"};
    return names[stage];
}

// What lab06-bench reads besides the time: per-kernel GPU time and resources, and how many
// paths each bounce's queues held, summed over the waves.
struct WavefrontStats {
    std::array<double, kStageCount> stage_ms{};       // CUDA events around each launch
    std::array<cudaFuncAttributes, kStageCount> attributes{};  // registers, local memory
    std::array<int, kStageCount> blocks_per_sm{};     // resident blocks of kStageThreads
    std::vector<long long> active_paths;              // [bounce]: active queue's size
    std::vector<long long> shadow_rays;               // [bounce]: shadow queue's size
    int waves = 0;
    int wave_paths = 0;       // the largest wave
    size_t bytes_per_path = 0;  // the pool (its queues and radiance), device memory per slot
};

// Paths per wave unless memory or the caller says fewer: 2^21 (2M) paths, about 0.34 GB of
// pool. Measured with lab06-bench's wave-size rows on an H200 (handouts/06-cuda-split.md).
constexpr long long kDefaultWavePaths = 1 << 21;

// The most paths of a wave: `wanted` (at least 1), and no more than half the GPU's free
// memory holds.
inline long long max_wave_paths(size_t bytes_per_path, long long wanted) {
    size_t free_bytes = 0, total_bytes = 0;
    check(cudaMemGetInfo(&free_bytes, &total_bytes), "reading the GPU's free memory");
    return std::min<long long>(std::max(1LL, wanted),
                               static_cast<long long>(free_bytes / 2 / bytes_per_path));
}

// What a wavefront lab's user may ask for: RT_LAB06_WAVE_PATHS lowers the wave size (the
// tests render small images in many waves so); read once, where the lab starts its render.
inline long long wave_paths_from_environment() {
    const char* limit = std::getenv("RT_LAB06_WAVE_PATHS");
    return limit ? std::min<long long>(kDefaultWavePaths, std::max(1LL, std::atoll(limit)))
                 : kDefaultWavePaths;
}

// The rows of a band and the samples of a wave: a band is as many whole rows as one wave's
// paths allow (at least one row), a wave as many samples of each of its pixels as fit.
struct WavePlan {
    int band_rows;
    int samples_per_wave;
};
inline WavePlan plan_waves(const RenderSettings& s, long long max_paths) {
    const long long rows = std::clamp<long long>(max_paths / s.width, 1, s.height);
    const long long samples = std::clamp<long long>(max_paths / (rows * s.width), 1, s.spp);
    return {static_cast<int>(rows), static_cast<int>(samples)};
}

// The launches of one wave's stages, what stage_loop.cuh's run_wave calls: each launch
// checked, and timed with CUDA events when stats are wanted.
template <class C>
class WaveStages {
public:
    using Pool = typename C::Pool;
    struct Memory {
        Pool pool;
        int* sizes;  // [0, bounces]: the path queue of each bounce; then the shadow queues
        SampleSum* sums;
        Vec3* means;
    };

    WaveStages(const WavefrontArgs& args, const Memory& memory, size_t shared_bytes,
               const std::array<unsigned, kStageCount>& grid, WavefrontStats* stats)
        : args_(args), memory_(memory), shared_bytes_(shared_bytes), grid_(grid), stats_(stats) {}
    ~WaveStages() {
        for (cudaEvent_t e : events_) cudaEventDestroy(e);
    }
    WaveStages(const WaveStages&) = delete;
    WaveStages& operator=(const WaveStages&) = delete;

    // The queues of bounce b: the paths about to make interaction number b (the pool's two
    // path queues take turns), and the shadow rays that interaction asks for.
    typename C::Paths active(int bounce) const {
        return {memory_.pool.paths[bounce % 2], memory_.sizes + bounce};
    }
    typename C::ShadowRays shadows(int bounce) const {
        return {memory_.pool.shadow_rays, memory_.sizes + args_.settings.bounces + 1 + bounce};
    }

    void generate_camera_paths(const typename C::Paths& active) {
        launch(kGenerate, [&] {
            ::generate_camera_paths<C>
                <<<grid_[kGenerate], kStageThreads>>>(args_, wave_, memory_.pool.radiance, active);
        });
    }
    void find_closest_hits(const typename C::Paths& active) {
        launch(kClosestHit, [&] {
            ::find_closest_hits<C>
                <<<queue_grid(kClosestHit), kStageThreads, shared_bytes_>>>(args_, active);
        });
    }
    // The bounce of the paths on `active` is where its counter lies: active(b)'s is sizes[b].
    void shade_hits(const typename C::Paths& active, const typename C::Paths& next,
                    const typename C::ShadowRays& shadows) {
        const int bounce = static_cast<int>(active.size - memory_.sizes);
        launch(kShade, [&] {
            ::shade_hits<C><<<queue_grid(kShade), kStageThreads, shared_bytes_>>>(
                args_, wave_, memory_.pool.radiance, bounce, active, next, shadows);
        });
    }
    void trace_shadow_rays(const typename C::ShadowRays& shadows) {
        launch(kShadow, [&] {
            ::trace_shadow_rays<C><<<queue_grid(kShadow), kStageThreads, shared_bytes_>>>(
                args_, memory_.pool.radiance, shadows);
        });
    }
    void accumulate_samples() {
        launch(kAccumulate, [&] {
            ::accumulate_samples<C><<<grid_[kAccumulate], kStageThreads>>>(
                wave_, memory_.pool.radiance, memory_.sums, last_wave_ ? memory_.means : nullptr,
                args_.settings.spp);
        });
    }

    // Runs one wave: empty queues, the stage loop, and (with stats) its timings and sizes.
    void run(const Wave& wave, bool last_wave_of_band) {
        wave_ = wave;
        last_wave_ = last_wave_of_band;
        launches_ = 0;
        const int counters = 2 * args_.settings.bounces + 1;
        check(cudaMemsetAsync(memory_.sizes, 0, counters * sizeof(int)), "emptying the queues");
        run_wave(*this, args_.settings.bounces);
        if (stats_) collect(counters);
    }

private:
    // Blocks for a kernel that pops a queue: one thread per path of the wave (no queue holds
    // more), or with C::kOneItemPerThread false enough to fill the GPU once.
    unsigned queue_grid(Stage stage) const {
        const unsigned covering =
            static_cast<unsigned>((wave_.paths() + kStageThreads - 1) / kStageThreads);
        return C::kOneItemPerThread ? std::max(grid_[stage], covering) : grid_[stage];
    }

    template <class Launch>
    void launch(Stage stage, Launch&& kernel_launch) {
        if (stats_) {
            while (events_.size() < 2 * (launches_ + 1)) {
                cudaEvent_t e = nullptr;
                check(cudaEventCreate(&e), "creating a CUDA event");
                events_.push_back(e);
            }
            stages_.resize(launches_ + 1);
            stages_[launches_] = stage;
            check(cudaEventRecord(events_[2 * launches_]), "recording a CUDA event");
        }
        kernel_launch();
        check(cudaGetLastError(), stage_name(stage));
        if (stats_) check(cudaEventRecord(events_[2 * launches_ + 1]), "recording a CUDA event");
        ++launches_;
    }

    void collect(int counters) {
        check(cudaDeviceSynchronize(), "running a wave");
        for (size_t i = 0; i < launches_; ++i) {
            float ms = 0;
            check(cudaEventElapsedTime(&ms, events_[2 * i], events_[2 * i + 1]),
                  "reading a CUDA event timer");
            stats_->stage_ms[stages_[i]] += ms;
        }
        std::vector<int> sizes(counters);
        check(
            cudaMemcpy(sizes.data(), memory_.sizes, counters * sizeof(int), cudaMemcpyDeviceToHost),
            "copying the queue sizes back");
        const int bounces = args_.settings.bounces;
        stats_->active_paths.resize(bounces, 0);
        stats_->shadow_rays.resize(bounces, 0);
        for (int b = 0; b < bounces; ++b) {
            stats_->active_paths[b] += sizes[b];
            stats_->shadow_rays[b] += sizes[bounces + 1 + b];
        }
        ++stats_->waves;
        stats_->wave_paths = std::max(stats_->wave_paths, wave_.paths());
    }

    WavefrontArgs args_;
    Memory memory_;
    size_t shared_bytes_;
    std::array<unsigned, kStageCount> grid_;
    WavefrontStats* stats_;
    Wave wave_{};
    bool last_wave_ = false;
    size_t launches_ = 0;
    std::vector<cudaEvent_t> events_;  // a start and a stop per launch of the wave (stats)
    std::vector<Stage> stages_;        // which stage each launch was
};

// Loads each kernel's module (CUDA loads lazily: else the first launch would do it inside
// the timed region) and sizes its grid to what fits on the GPU at once.
template <class C>
std::array<unsigned, kStageCount> prepare_stages(const cudaDeviceProp& prop, size_t shared_bytes,
                                                 WavefrontStats* stats) {
    const std::array<const void*, kStageCount> kernels = {
        reinterpret_cast<const void*>(generate_camera_paths<C>),
        reinterpret_cast<const void*>(find_closest_hits<C>),
        reinterpret_cast<const void*>(shade_hits<C>),
        reinterpret_cast<const void*>(trace_shadow_rays<C>),
        reinterpret_cast<const void*>(accumulate_samples<C>)};
    std::array<unsigned, kStageCount> grid{};
    for (int s = 0; s < kStageCount; ++s) {
        const bool reads_scene = s == kClosestHit || s == kShade || s == kShadow;
        cudaFuncAttributes attributes{};
        check(cudaFuncGetAttributes(&attributes, kernels[s]), "loading a wavefront kernel");
        int blocks = 0;
        check(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&blocks, kernels[s], kStageThreads,
                                                            reads_scene ? shared_bytes : 0),
              "computing a wavefront kernel's occupancy");
        if (blocks == 0)
            throw GpuError(std::string("GPU: ") + stage_name(s) + " cannot run on this GPU");
        grid[s] = static_cast<unsigned>(blocks * prop.multiProcessorCount);
        if (stats) {
            stats->attributes[s] = attributes;
            stats->blocks_per_sm[s] = blocks;
        }
    }
    return grid;
}

// Renders the job with the kernels of Config C, at most wave_paths paths a wave. Returns the
// GPU seconds of all stages.
template <class C>
double render_waves(const RenderJob& job, const cudaDeviceProp& prop, const SceneLayout& layout,
                    const float4* scene_pool, long long wave_paths, Image& image,
                    WavefrontStats* stats) {
    using Pool = typename C::Pool;
    const RenderSettings& settings = job.settings;
    const size_t shared_bytes = C::kSceneMemory == SceneMemory::Shared ? layout.bytes() : 0;
    const std::array<unsigned, kStageCount> grid = prepare_stages<C>(prop, shared_bytes, stats);

    const size_t bytes_per_path = Pool::bytes_for(1024) / 1024;
    const WavePlan plan = plan_waves(settings, max_wave_paths(bytes_per_path, wave_paths));
    const int band_pixels = plan.band_rows * settings.width;
    const int slots = band_pixels * plan.samples_per_wave;
    if (stats) stats->bytes_per_path = bytes_per_path;

    DeviceArray<unsigned char> pool_memory(Pool::bytes_for(slots), "allocating the path pool");
    DeviceArray<int> sizes(2 * settings.bounces + 1, "allocating the queue sizes");
    DeviceArray<SampleSum> sums(band_pixels, "allocating the pixel sums");
    DeviceArray<Vec3> means(band_pixels, "allocating the image band");
    const typename WaveStages<C>::Memory memory{Pool::carve(pool_memory.data(), slots),
                                                sizes.data(), sums.data(), means.data()};
    const WavefrontArgs args{layout, scene_pool, job.camera, settings};
    WaveStages<C> stages(args, memory, shared_bytes, grid, stats);

    double seconds = 0;
    GpuTimer timer;
    for (int first_row = 0; first_row < settings.height; first_row += plan.band_rows) {
        const int rows = std::min(plan.band_rows, settings.height - first_row);
        const int pixels = rows * settings.width;
        timer.start();
        check(cudaMemsetAsync(sums.data(), 0, pixels * sizeof(SampleSum)),
              "clearing the pixel sums");
        for (int first = 0; first < settings.spp; first += plan.samples_per_wave) {
            const int samples = std::min(plan.samples_per_wave, settings.spp - first);
            stages.run({first_row * settings.width, pixels, first, samples},
                       first + samples == settings.spp);
        }
        timer.stop();
        seconds += timer.seconds();
        check_launch("rendering a band of rows");
        check(cudaMemcpy(&image.at(0, first_row), means.data(), pixels * sizeof(Vec3),
                         cudaMemcpyDeviceToHost),
              "copying the pixels back from the GPU");
        job.progress.rows_done(rows);
    }
    return seconds;
}

// The whole render() of a wavefront lab, for path-pool layout Layout: the scene in each
// block's shared memory when it is small, else in global memory (lab 05's rule,
// choose_scene_memory), a shading kernel for the scene's material kinds, and kernels for its
// primitive kinds: BoxGeometry (spheres and axis-aligned rectangles, the Cornell box) when
// that holds the scene, else every kind.
template <class Layout>
RenderStats render_wavefront(const RenderJob& job, Image& image, WavefrontStats* stats = nullptr) {
    const cudaDeviceProp prop = open_device();
    const SceneLayout layout = layout_of(job.scene);
    const std::vector<float4> host_pool = pack(job.scene, layout);
    DeviceArray<float4> scene_pool(host_pool.size(), "allocating the scene on the GPU");
    check(
        cudaMemcpy(scene_pool.data(), host_pool.data(), scene_pool.bytes(), cudaMemcpyHostToDevice),
        "copying the scene to the GPU");
    const bool shared = choose_scene_memory(layout) == SceneMemory::Shared;
    const bool specular = has_specular_material(job.scene.materials, job.scene.num_materials);
    const bool box = geometry_kinds(job.scene).fits<BoxGeometry>();
    const long long wave_paths = wave_paths_from_environment();
    using S = std::integral_constant<SceneMemory, SceneMemory::Shared>;
    using G = std::integral_constant<SceneMemory, SceneMemory::Global>;
    const auto render = [&](auto memory, auto materials, auto primitives) {
        using C = WavefrontConfig<Layout, decltype(memory)::value, Reserve::kPerBlock,
                                  decltype(materials), 1, false, true, decltype(primitives)>;
        return render_waves<C>(job, prop, layout, scene_pool.data(), wave_paths, image, stats);
    };
    const auto in = [&](auto memory, auto materials) {
        return box ? render(memory, materials, BoxGeometry{})
                   : render(memory, materials, AnyGeometry{});
    };
    const double seconds = shared ? (specular ? in(S{}, AnyMaterial{}) : in(S{}, DiffuseOnly{}))
                                  : (specular ? in(G{}, AnyMaterial{}) : in(G{}, DiffuseOnly{}));
    return {seconds, describe(prop), kKernelTimeOnly, describe_layout<Layout>()};
}
