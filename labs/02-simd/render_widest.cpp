// Lab 02's reference at the width this CPU has (./lab02-ref): 16 paths per AVX-512 packet
// where the CPU runs them, else 8 per AVX2 packet, and in both cases compacted packets
// (common/simd/compacted_tracer.h): the paths of a run of samples advance bounce by bounce
// and the survivors are repacked into full packets. The image is lab 01's, bit for bit.
//
// This file is built without SIMD flags: it checks the CPU, then calls the SIMD library's
// objects (common/simd/packet_renderer.h). What students write is the 8-lane packet of
// solution/ (./lab02-ref-avx2, their speed's yardstick); handout section 8 goes from there
// to this.
//
// Built with -DRT_PACKETS_FROM_ENV (./lab02-bench), it renders with the width and method that
// RT_SIMD_LANES (8 or 16) and RT_SIMD_COMPACT (0 or 1) name, for the handout's table, and with
// RT_SIMD_LANE_USE=1 it then traces the image's paths again, untimed, counting how full the
// packets were at each bounce, and prints that on stderr.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "cpu_features.h"
#include "lab.h"
#include "packet_renderer.h"
#include "timer.h"

const char* const kLabName = "02-simd";

namespace {

#if defined(RT_PACKETS_FROM_ENV)
// An environment variable as an int, or `fallback` when it is unset or empty.
int environment_int(const char* name, int fallback) {
    const char* value = std::getenv(name);
    if (value == nullptr || *value == '\0') return fallback;
    char* end = nullptr;
    const long parsed = std::strtol(value, &end, 10);
    if (*end != '\0' || parsed < 0 || parsed > 64) {
        throw InputError(std::string(name) + " must be a small integer, not '" + value + "'");
    }
    return static_cast<int>(parsed);
}

PacketRenderer chosen_renderer() {
    const PacketRenderer widest = widest_packet_renderer();
    return packet_renderer(environment_int("RT_SIMD_LANES", widest.lanes),
                           environment_int("RT_SIMD_COMPACT", 1) != 0);
}

void report_lane_use(const PacketRenderer& packets, const RenderJob& job) {
    if (environment_int("RT_SIMD_LANE_USE", 0) == 0) return;
    LaneUse use;
    const long pixels = static_cast<long>(job.settings.width) * job.settings.height;
    for (long first = 0; first < pixels; first += job.settings.width) {
        packets.count(job.scene, job.camera, job.settings, first, job.settings.width,
                      packets.compacted, use);
    }
    std::fprintf(stderr, "%s\n", packets.describe().c_str());
    use.print(stderr, packets.lanes);
}
#else
PacketRenderer chosen_renderer() { return widest_packet_renderer(); }
void report_lane_use(const PacketRenderer&, const RenderJob&) {}
#endif

}  // namespace

RenderStats render(const RenderJob& job, Image& image) {
    require_avx2("lab 02 (AVX2 or AVX-512 packets)", cpu_model_name());
    const PacketRenderer packets = chosen_renderer();
    const RenderSettings& settings = job.settings;
    const Timer timer;
    // A row at a time: a compacted group runs across the pixels of a row (256 paths are 4
    // pixels at 64 spp), so its packets stay full to the row's end.
    for (int y = 0; y < settings.height; ++y) {
        packets.render(job.scene, job.camera, settings, static_cast<long>(y) * settings.width,
                       settings.width, &image.at(0, y));
        job.progress.rows_done();
    }
    const double seconds = timer.seconds();
    report_lane_use(packets, job);
    return {seconds, cpu_model_name() + ", 1 thread, " + packets.describe()};
}
