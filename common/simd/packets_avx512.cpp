// The packet tracer on Float16: packet_renderer.h's render functions of this width. Built with
// the Makefile's SIMD_AVX512_FLAGS; called only through packet_renderer.cpp, once the CPU is checked.
#include <simd16.h>
// (the header above first: it defines the lane type the templates below are used with)
#include <compacted_tracer.h>
#include <lane_census.h>
#include <packet_tracer.h>

#include <vector>

// Pixel after pixel, each one's samples in packets traced from camera to end
// (packet_tracer.h, with the intersection tests lab 02's students write: packet_hits.h).
void render_pixels_avx512(const SceneView& scene, const Camera& camera,
                          const RenderSettings& settings, long first_pixel, int pixel_count,
                          Vec3* out) {
    for (int i = 0; i < pixel_count; ++i) {
        const long p = first_pixel + i;
        out[i] = render_pixel_packets<Float16>(scene, camera, settings,
                                               static_cast<int>(p % settings.width),
                                               static_cast<int>(p / settings.width));
    }
}

// The run's samples in groups whose packets are refilled after every bounce
// (compacted_tracer.h).
void render_pixels_avx512_compacted(const SceneView& scene, const Camera& camera,
                                    const RenderSettings& settings, long first_pixel,
                                    int pixel_count, Vec3* out) {
    render_pixels_compacted<Float16>(scene, camera, settings, first_pixel, pixel_count, out);
}

// How full the packets of either method are, bounce by bounce (lab02-bench's
// RT_SIMD_LANE_USE): the same paths as the functions above, counted, not summed.
void count_lanes_avx512(const SceneView& scene, const Camera& camera,
                        const RenderSettings& settings, long first_pixel, int pixel_count,
                        bool compacted, LaneUse& use) {
    if (compacted) {
        std::vector<Vec3> discarded(static_cast<size_t>(pixel_count));
        render_pixels_compacted<Float16>(scene, camera, settings, first_pixel, pixel_count,
                                         discarded.data(), &use);
        return;
    }
    for (int i = 0; i < pixel_count; ++i) {
        const long p = first_pixel + i;
        count_pixel_lanes<Float16>(scene, camera, settings, static_cast<int>(p % settings.width),
                                   static_cast<int>(p / settings.width), use);
    }
}
