// A megakernel for small diffuse scenes of spheres and axis-aligned rectangles (the Cornell
// box): the scene's counts are template parameters, so the primitive loops unroll and every
// primitive's numbers are constant-bank operands at addresses known when the kernel is
// compiled (no loop counter, no address arithmetic, no load by index). lab05-ref gives it every
// scene it holds (is_small_scene; kernel_choice.cuh's with_small_scene_choice picks the counts),
// the kinds kernel (render_kernel.cuh's whole paths) every other; lab05-bench times it as
// "reference" against that kernel ("kinds-kernel") and in its "small-" shapes.
//
// What a path does is the core's (path_tracer.h's trace_path over path_steps.h's steps): the
// same tests in the same order (each sphere, then each rectangle as a slab, rect_slabs.cuh),
// the same light sample (sample_light), offset and cosine-sampled bounce, with the same
// operations on the same numbers, so the image is the reference kernel's up to the
// compiler's fused multiply-adds (lab05-bench says whether bit for bit). What differs is how
// the kernel reaches the numbers:
//  - the hit's surface (normal, extent, albedo) is chosen by selects between constant-bank
//    operands, not loaded by the hit's index from the primitive and then from the material
//    table (loads whose addresses differ across a warp's lanes, which the constant cache
//    serves one address at a time);
//  - the shadow ray is tested only against the rectangles that can come between a surface
//    point and the light (SmallScene::shadow_rects, decided once per scene on the host);
//  - a sample's random-number key is one hash from its pixel's (PixelKey), not three.
#pragma once

#include <cuda_runtime.h>

#include <cmath>
#include <cstdint>
#include <cstring>

#include <cuda_check.h>
#include <megakernel_parts.cuh>

// The largest counts a small-scene kernel is meant for (is_small_scene): its bank holds a scene
// of up to these; each pair of counts is a kernel of its own.
constexpr int kSmallSceneMaxSpheres = 2;
constexpr int kSmallSceneMaxRects = 6;

// The numbers a small-scene kernel reads, laid out for kSpheres spheres and kRects rectangles
// (one instantiation per pair of counts), copied into its own part of the constant bank.
template <int kSpheres, int kRects>
struct SmallScene {
    static constexpr int kS = kSpheres > 0 ? kSpheres : 1;  // no arrays of length 0
    static constexpr int kR = kRects > 0 ? kRects : 1;
    Sphere spheres[kS];
    RectSlab slabs[kR];
    Vec3 sphere_albedo[kS];  // each primitive's material's albedo
    real sphere_extent[kS];  // sphere_extent(s): offset_ray_origin's extent
    Vec3 rect_normal[kR];    // rect_normal(r), the core's: the same bits, signed zeros too
    real rect_extent[kR];
    Vec3 rect_albedo[kR];
    unsigned shadow_rects;   // bit i: rectangle i can block a shadow ray (small_shadow_rects)
};

constexpr size_t kSmallSceneBytes = sizeof(SmallScene<kSmallSceneMaxSpheres, kSmallSceneMaxRects>);
__constant__ float4 small_scene_bank[(kSmallSceneBytes + 15) / 16];

template <int kSpheres, int kRects>
__device__ __forceinline__ const SmallScene<kSpheres, kRects>& small_scene() {
    return *reinterpret_cast<const SmallScene<kSpheres, kRects>*>(small_scene_bank);
}

// Whether a scene is one the small-scene kernels render: diffuse only, spheres and rectangles
// only, at most the counts above.
inline bool is_small_scene(const SceneView& scene, bool specular) {
    const GeometryKinds kinds = geometry_kinds(scene);
    return !specular && kinds.fits<BoxGeometry>() &&
           scene.of<Sphere>().count <= kSmallSceneMaxSpheres &&
           scene.of<AxisRect>().count <= kSmallSceneMaxRects;
}

// Whether a shadow ray may cross the plane {p_axis = c}'s rectangle: which rectangles the
// shadow test must visit. A rectangle can be skipped when the light lies strictly on one side
// of its plane and every primitive in the closed half-space on that side (spheres clear of
// the plane by more than any ray offset): a shadow ray then starts at a surface point's
// offset origin, on the light's side (a lit point's offset goes along a normal facing the
// light) or on the plane, and runs toward the light, so it crosses the plane at t <= 0. The
// slab test computes that crossing as c * (1/d) - o * (1/d) with one rounding; for a ray that
// starts on the plane (o = c) it is exactly 0, and so no hit, when c * (1/d) is exact: c zero
// or a power of two, which the rule asks too (the Cornell box's walls lie at such numbers).
// A sphere must clear the plane: near where it touches it, a point's offset origin may lie
// past the plane. So in the Cornell box the four walls are skipped and the floor, on which
// the sphere rests, is not.
inline unsigned small_shadow_rects(const SceneView& scene) {
    const KindSpan<AxisRect> rects = scene.of<AxisRect>();
    const KindSpan<Sphere> spheres = scene.of<Sphere>();
    unsigned mask = 0;
    for (int i = 0; i < rects.count; ++i) {
        const RectSlab s = rect_slab(rects[i]);
        const int axis = rect_axis(rects[i]);
        const real lo[3] = {s.lo_x, s.lo_y, s.lo_z};
        const real c = lo[axis];
        const real light = scene.light.position[axis];
        int exponent = 0;
        const bool exact = c == real(0) || std::frexp(std::fabs(c), &exponent) == real(0.5);
        const real side = light > c ? real(1) : real(-1);
        bool skip = scene.has_light && exact && light != c && std::isfinite(light);
        for (int j = 0; skip && j < rects.count; ++j) {
            const RectSlab o = rect_slab(rects[j]);
            const real olo[3] = {o.lo_x, o.lo_y, o.lo_z}, ohi[3] = {o.hi_x, o.hi_y, o.hi_z};
            skip = (olo[axis] - c) * side >= 0 && (ohi[axis] - c) * side >= 0;
        }
        for (int j = 0; skip && j < spheres.count; ++j) {
            const Sphere& sp = spheres[j];
            const real gap = (sp.center[axis] - c) * side - sp.radius;
            skip = gap > real(1e-3) * (std::fabs(c) + sphere_extent(sp));
        }
        if (!skip) mask |= 1u << i;
    }
    return mask;
}

// The small-scene kernels' numbers for a scene (is_small_scene), copied into the bank.
template <int kSpheres, int kRects>
inline SmallScene<kSpheres, kRects> small_scene_of(const SceneView& scene) {
    SmallScene<kSpheres, kRects> s{};
    for (int i = 0; i < kSpheres; ++i) {
        const Sphere& sp = scene.of<Sphere>()[i];
        s.spheres[i] = sp;
        s.sphere_albedo[i] = scene.materials[sp.material].albedo;
        s.sphere_extent[i] = sphere_extent(sp);
    }
    for (int i = 0; i < kRects; ++i) {
        const AxisRect& r = scene.of<AxisRect>()[i];
        s.slabs[i] = rect_slab(r);
        s.rect_normal[i] = rect_normal(r);
        s.rect_extent[i] = r.extent;
        s.rect_albedo[i] = scene.materials[r.material].albedo;
    }
    s.shadow_rects = small_shadow_rects(scene);
    return s;
}

template <int kSpheres, int kRects>
inline void upload_small_scene(const SceneView& scene) {
    const SmallScene<kSpheres, kRects> s = small_scene_of<kSpheres, kRects>(scene);
    static_assert(sizeof s <= kSmallSceneBytes, "the bank holds the largest small scene");
    check(cudaMemcpyToSymbol(small_scene_bank, &s, sizeof s),
          "copying the scene to the GPU's constant memory");
}

// The part of a sample's key that depends on the seed and the pixel only: SampleStream's first
// two hashes (rng.h), so that a sample's stream costs one hash more.
struct PixelKey {
    uint64_t bits;

    __device__ PixelKey(uint64_t seed, uint64_t pixel)
        : bits(mix64(mix64(seed ^ 0x9e3779b97f4a7c15ull) ^ pixel)) {}

    // SampleStream(seed, pixel, sample), bit for bit: rng.h's constructor with its first two
    // hashes taken from here.
    __device__ SampleStream stream(uint64_t sample) const {
        static_assert(sizeof(SampleStream) == sizeof(uint64_t), "one 64-bit key");
        const uint64_t key = mix64(bits ^ sample);
        SampleStream s(0, 0, 0);
        memcpy(&s, &key, sizeof key);
        return kept_in_registers(s);
    }
};

// The closest hit: which primitive (-1: none; spheres 0..kSpheres-1, then the rectangles) and
// at what distance, by the core's tests in the core's order with its strict comparison.
struct SmallHit {
    real t;
    int id;
};

// The surface at a hit, chosen as the hit is found.
struct SmallSurface {
    Vec3 normal;
    real extent;
    Vec3 albedo;
};

template <class T>
__device__ __forceinline__ T pick(bool c, T a, T b) {
    return c ? a : b;
}
__device__ __forceinline__ Vec3 pick(bool c, Vec3 a, Vec3 b) {
    return {c ? a.x : b.x, c ? a.y : b.y, c ? a.z : b.z};
}

template <int kSpheres, int kRects>
__device__ __forceinline__ SmallHit small_closest_hit(const Ray& ray) {
    const SmallScene<kSpheres, kRects>& scene = small_scene<kSpheres, kRects>();
    SmallHit hit{kRealMax, -1};
#pragma unroll
    for (int i = 0; i < kSpheres; ++i) {
        const real t = intersect(ray, scene.spheres[i], hit.t);
        if (t < hit.t) hit = {t, i};
    }
    if constexpr (kRects > 0) {
        const SlabRay slab_ray(ray);
#pragma unroll
        for (int i = 0; i < kRects; ++i) {
            const SlabSpan span = slab_span(slab_ray, scene.slabs[i]);
            if (slab_hit(span, hit.t)) hit = {span.entry, kSpheres + i};
        }
    }
    return hit;
}

// The surface of a found hit at `position`. A sphere's normal takes a square root and a
// division: only the lanes on a sphere compute it (a branch), the rectangles' numbers are
// selects between operands of the bank (kBySelects), or loaded by the hit's index.
template <int kSpheres, int kRects, bool kBySelects>
__device__ __forceinline__ SmallSurface small_surface(const SmallHit& hit, Vec3 position) {
    const SmallScene<kSpheres, kRects>& scene = small_scene<kSpheres, kRects>();
    SmallSurface s;
    if (kSpheres > 0 && hit.id < kSpheres) {
        Vec3 center = scene.spheres[0].center;
        s.extent = scene.sphere_extent[0];
        s.albedo = scene.sphere_albedo[0];
#pragma unroll
        for (int i = 1; i < kSpheres; ++i) {
            const bool here = hit.id == i;
            center = pick(here, scene.spheres[i].center, center);
            s.extent = pick(here, scene.sphere_extent[i], s.extent);
            s.albedo = pick(here, scene.sphere_albedo[i], s.albedo);
        }
        s.normal = normalize(position - center);
    } else if constexpr (kRects > 0) {
        if constexpr (kBySelects) {
            s.normal = scene.rect_normal[0];
            s.extent = scene.rect_extent[0];
            s.albedo = scene.rect_albedo[0];
#pragma unroll
            for (int i = 1; i < kRects; ++i) {
                const bool here = hit.id == kSpheres + i;
                s.normal = pick(here, scene.rect_normal[i], s.normal);
                s.extent = pick(here, scene.rect_extent[i], s.extent);
                s.albedo = pick(here, scene.rect_albedo[i], s.albedo);
            }
        } else {
            const int k = hit.id - kSpheres;
            s.normal = scene.rect_normal[k];
            s.extent = scene.rect_extent[k];
            s.albedo = scene.rect_albedo[k];
        }
    }
    return s;
}

// Whether anything blocks the shadow ray before t_max: every sphere, and the rectangles
// that can lie between a surface and the light (all of them unless kCull).
template <int kSpheres, int kRects, bool kCull>
__device__ __forceinline__ bool small_occluded(const Ray& ray, real t_max) {
    const SmallScene<kSpheres, kRects>& scene = small_scene<kSpheres, kRects>();
    bool blocked = false;
#pragma unroll
    for (int i = 0; i < kSpheres; ++i) blocked |= occludes(ray, scene.spheres[i], t_max);
    if constexpr (kRects > 0) {
        const unsigned mask = kCull ? scene.shadow_rects : ~0u;
        if (mask != 0) {  // the same for every lane: a branch the warp takes together
            const SlabRay slab_ray(ray);
#pragma unroll
            for (int i = 0; i < kRects; ++i) {
                if (mask & (1u << i))
                    blocked |= slab_hit(slab_span(slab_ray, scene.slabs[i]), t_max);
            }
        }
    }
    return blocked;
}

// A thread's samples first, first + stride, ... of pixel (x, y), whole paths one after the
// other as trace_samples does (render_kernel.cuh), each path the core's trace_path step for
// step: closest hit, the surface, the light sample and its shadow ray, the next ray.
template <int kSpheres, int kRects, bool kCull, bool kBySelects>
__device__ inline SampleSum trace_samples_small(const SceneView& scene, const KernelArgs& args,
                                                int x, int y, uint64_t pixel, int first,
                                                int stride) {
    SampleSum sum;
    const PixelKey key(args.settings.seed, pixel);
    const int bounces = args.settings.bounces;
    for (int s = first; s < args.settings.spp; s += stride) {
        const SampleStream rng = key.stream(static_cast<uint64_t>(s));
        Ray ray =
            args.camera.ray_through(x + real(rng.at(kDimPixelX)), y + real(rng.at(kDimPixelY)));
        Vec3 throughput(1.0f), radiance(0.0f);
        for (int bounce = 0; bounce < bounces; ++bounce) {
            const SmallHit hit = small_closest_hit<kSpheres, kRects>(ray);
            if (hit.id < 0) {
                radiance += throughput * scene.background;
                break;
            }
            const Vec3 position = ray.at(hit.t);
            const SmallSurface surface = small_surface<kSpheres, kRects, kBySelects>(hit, position);
            const Vec3 incoming = ray.direction;
            const bool entering = dot(incoming, surface.normal) < 0.0f;
            const Vec3 facing = entering ? surface.normal : -surface.normal;
            const Vec3 above = offset_ray_origin(position, facing, hit.t, surface.extent);
            ShadowRay shadow;
            const bool lit = scene.has_light &&
                             sample_light(scene, position, above, facing, surface.albedo, shadow);
            const Vec3 shadow_radiance = throughput * shadow.radiance;
            if (bounce + 1 < bounces) {
                throughput *= surface.albedo;
                ray = {above, sample_cosine_hemisphere(facing, rng.at(bounce_dimension(bounce, 0)),
                                                       rng.at(bounce_dimension(bounce, 1)))};
            }
            if (lit && !small_occluded<kSpheres, kRects, kCull>(shadow.ray, shadow.t_max))
                radiance += shadow_radiance;
        }
        sum.add(radiance);
    }
    return sum;
}

// The small-scene kernel: render_kernel's work split (kThreadsPerPixel threads per pixel,
// their sums added across the warp), the paths of trace_samples_small.
template <int kSpheres, int kRects, int kThreadsPerPixel, int kBlockThreads, int kMaxRegisters,
          bool kCull = true, bool kBySelects = true>
__global__ void __launch_bounds__(kBlockThreads) __maxnreg__(kMaxRegisters)
    small_scene_kernel(const KernelArgs args) {
    const SceneView scene = args.layout.view(args.scene_pool);  // light and background only
    const int width = args.settings.width;
    const long long thread = static_cast<long long>(blockIdx.x) * kBlockThreads + threadIdx.x;
    const long long band_pixel = thread / kThreadsPerPixel;
    const int first_sample = static_cast<int>(thread % kThreadsPerPixel);
    const bool inside = band_pixel < static_cast<long long>(args.rows) * width;
    const int x = static_cast<int>(band_pixel % width);
    const int y = args.first_row + static_cast<int>(band_pixel / width);
    const uint64_t pixel = static_cast<uint64_t>(y) * width + x;
    SampleSum sum;
    if (inside) {
        sum = trace_samples_small<kSpheres, kRects, kCull, kBySelects>(
            scene, args, x, y, pixel, first_sample, kThreadsPerPixel);
    }
    sum = sum_across_lanes<kThreadsPerPixel>(sum);
    if (inside && first_sample == 0) args.pixels[band_pixel] = sum.mean(args.settings.spp);
}
