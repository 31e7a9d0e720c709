// Microbenchmarks of the shared renderer's inner loops (Google Benchmark): where a path's
// time goes. `make bench-micro` prints the table.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "cli.h"
#include "path_tracer.h"
#include "scene_loader.h"

namespace {

const Scene& cornell() {
    static const Scene scene = load_scene(default_scene_path());
    return scene;
}

// Rays as a render makes them: from the camera through random pixels, then bounced once.
std::vector<Ray> sample_rays(size_t n) {
    const Scene& scene = cornell();
    const SceneView view = scene.view();
    const Camera camera = scene.camera.for_image(600, 600);
    std::vector<Ray> rays;
    for (size_t i = 0; rays.size() < n; ++i) {
        const SampleStream rng(1, i, 0);
        const Ray primary = camera.ray_through(600 * rng.at(0), 600 * rng.at(1));
        const Hit hit = closest_hit(view, primary);
        if (!hit.found()) continue;
        const SurfacePoint s = surface_at(view, primary, hit);
        const Vec3 facing = dot(primary.direction, s.normal) < 0 ? s.normal : -s.normal;
        rays.push_back({offset_ray_origin(s.position, facing, hit.t, s.extent),
                        sample_cosine_hemisphere(facing, rng.at(2), rng.at(3))});
    }
    return rays;
}

void BM_closest_hit_cornell(benchmark::State& state) {
    const SceneView view = cornell().view();
    const std::vector<Ray> rays = sample_rays(4096);
    size_t i = 0;
    for (auto _ : state) benchmark::DoNotOptimize(closest_hit(view, rays[i++ & 4095]));
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_closest_hit_cornell);

void BM_occluded_cornell(benchmark::State& state) {
    const Scene& scene = cornell();
    const SceneView view = scene.view();
    const std::vector<Ray> rays = sample_rays(4096);
    size_t i = 0;
    for (auto _ : state) {
        const Ray& r = rays[i++ & 4095];
        const Vec3 to_light = scene.light.position - r.origin;
        const float d = length(to_light);
        benchmark::DoNotOptimize(occluded(view, {r.origin, to_light / d}, d));
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_occluded_cornell);

// The Cornell box's five walls as each kind of flat primitive: rectangles (as it loads),
// convex quads, and two triangles each (as every quad loaded before they had kinds).
struct Walls {
    std::vector<AxisRect> rects;
    std::vector<ConvexQuad> quads;
    std::vector<Triangle> triangles;
};
const Walls& walls() {
    static const Walls w = [] {
        Walls out;
        out.rects = cornell().of<AxisRect>();
        for (const AxisRect& r : out.rects) {
            Vec3 c[4];
            rect_corners(r, c);
            out.quads.push_back(make_convex_quad(c[0], c[1], c[2], c[3], r.material));
            out.triangles.push_back(make_triangle(c[0], c[1], c[2], r.material));
            out.triangles.push_back(make_triangle(c[0], c[2], c[3], r.material));
        }
        return out;
    }();
    return w;
}

// One wall per iteration: a rectangle, a quad, or a quad's worth of triangles (two tests).
void BM_intersect_triangle_pair(benchmark::State& state) {
    const std::vector<Triangle>& tris = walls().triangles;
    const std::vector<Ray> rays = sample_rays(4096);
    size_t i = 0;
    for (auto _ : state) {
        const Ray& r = rays[i & 4095];
        const RayShear shear(r.direction);
        const size_t w = 2 * (i++ % (tris.size() / 2));
        const float t = intersect_triangle(r, shear, tris[w], 1e30f);
        benchmark::DoNotOptimize(intersect_triangle(r, shear, tris[w + 1], t));
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_intersect_triangle_pair);

void BM_intersect_quad(benchmark::State& state) {
    const std::vector<ConvexQuad>& quads = walls().quads;
    const std::vector<Ray> rays = sample_rays(4096);
    size_t i = 0;
    for (auto _ : state) {
        const Ray& r = rays[i & 4095];
        const RayShear shear(r.direction);
        benchmark::DoNotOptimize(intersect_quad(r, shear, quads[i++ % quads.size()], 1e30f));
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_intersect_quad);

void BM_intersect_rect(benchmark::State& state) {
    const std::vector<AxisRect>& rects = walls().rects;
    const std::vector<Ray> rays = sample_rays(4096);
    size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(intersect_rect(rays[i & 4095], rects[i % rects.size()], 1e30f));
        ++i;
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_intersect_rect);

void BM_intersect_sphere(benchmark::State& state) {
    const Scene& scene = cornell();
    const std::vector<Ray> rays = sample_rays(4096);
    size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(intersect_sphere(rays[i++ & 4095], scene.of<Sphere>()[0], 1e30f));
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_intersect_sphere);

void BM_trace_path_cornell(benchmark::State& state) {
    const Scene& scene = cornell();
    const SceneView view = scene.view();
    const Camera camera = scene.camera.for_image(600, 600);
    uint64_t i = 0;
    for (auto _ : state) {
        const SampleStream rng(0, i++, 0);
        const Ray ray = camera.ray_through(600 * rng.at(0), 600 * rng.at(1));
        benchmark::DoNotOptimize(trace_path(view, ray, rng, 4));
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_trace_path_cornell);

}  // namespace

BENCHMARK_MAIN();
