// Lane use of packet_tracer.h's packets, counted (lane_use.h): render_pixel_packets' loop
// with a tally of the alive lanes at each bounce. Only for measuring (lab02-bench,
// RT_SIMD_LANE_USE=1): the renderers themselves count nothing.
#pragma once

#include <lane_use.h>
#include <packet_tracer.h>

// trace_paths' loop for the samples of pixel (x, y), tallying each bounce's packets and
// alive lanes in `use`.
template <class F>
inline void count_pixel_lanes(const SceneView& scene, const Camera& camera,
                              const RenderSettings& settings, int x, int y, LaneUse& use) {
    constexpr int kLanes = F::kLanes;
    const uint64_t pixel = static_cast<uint64_t>(y) * settings.width + x;
    for (int s = 0; s < settings.spp; s += kLanes) {
        const int count = settings.spp - s < kLanes ? settings.spp - s : kLanes;
        const SampleStreamN<F> rng(settings.seed, pixel, s);
        const RayPacket<F> ray = camera_rays(camera, F(static_cast<float>(x)) + rng.at(kDimPixelX),
                                             F(static_cast<float>(y)) + rng.at(kDimPixelY));
        PathPacket<F> path{ray, Vec3xN<F>(Vec3(1.0f)), Vec3xN<F>(Vec3(0.0f)), 0,
                           settings.bounces > 0 ? MaskOf<F>::first(count) : MaskOf<F>::none()};
        while (any(path.alive)) {
            use.add(path.bounce, 1, __builtin_popcount(path.alive.bits()));
            const HitPacket<F> hit = closest_hit(scene, path.ray, path.alive);
            ShadowPacket<F> shadow{};
            const auto lit = bounce_step(scene, hit, rng, settings.bounces, path, shadow);
            add_unblocked_light(scene, lit, shadow, path);
        }
    }
}
