// The choice of packet width at run time (packet_renderer.h). Built without SIMD flags: it
// runs before anyone knows what the CPU has.
#include "packet_renderer.h"

#include <cpu_features.h>
#include <lab.h>

// Defined in packets_avx2.cpp and packets_avx512.cpp.
void render_pixels_avx2(const SceneView&, const Camera&, const RenderSettings&, long, int, Vec3*);
void render_pixels_avx2_compacted(const SceneView&, const Camera&, const RenderSettings&, long, int,
                                  Vec3*);
void render_pixels_avx512(const SceneView&, const Camera&, const RenderSettings&, long, int, Vec3*);
void render_pixels_avx512_compacted(const SceneView&, const Camera&, const RenderSettings&, long,
                                    int, Vec3*);
void count_lanes_avx2(const SceneView&, const Camera&, const RenderSettings&, long, int, bool,
                      LaneUse&);
void count_lanes_avx512(const SceneView&, const Camera&, const RenderSettings&, long, int, bool,
                        LaneUse&);

std::string PacketRenderer::describe() const {
    return std::string(lanes == 16 ? "AVX-512" : "AVX2") + ", " + std::to_string(lanes) +
           " paths per packet" + (compacted ? ", compacted" : "");
}

PacketRenderer packet_renderer(int lanes, bool compacted) {
    if (lanes == 8) {
        require_avx2("8-lane packets (AVX2)", cpu_model_name());
        return {compacted ? render_pixels_avx2_compacted : render_pixels_avx2, count_lanes_avx2, 8,
                compacted};
    }
    if (lanes != 16) {
        throw InputError("packets have 8 (AVX2) or 16 (AVX-512) lanes, not " +
                         std::to_string(lanes));
    }
    if (!cpu_has_avx512()) {
        throw MissingCpuFeature(
            "16-lane packets need a CPU with AVX-512 (F, DQ, VL, BW), and "
            "this one (" +
            cpu_model_name() + ") has not" +
            (forced_off("RT_FORCE_NO_AVX512") ? " (RT_FORCE_NO_AVX512 is set)" : ""));
    }
    return {compacted ? render_pixels_avx512_compacted : render_pixels_avx512, count_lanes_avx512,
            16, compacted};
}

PacketRenderer widest_packet_renderer() { return packet_renderer(cpu_has_avx512() ? 16 : 8, true); }
