// The speed a GPU reference is held to. The tests assert only thresholds that a slower
// clock of the same GPU still passes with a wide margin; the real bars live here, and the
// benchmarks print them next to what they measured, with whether this run meets them.
// A bar is set for the GPUs the course may get (kTargetGpus) and the baseline render (the
// Cornell box at 600x600, 512 spp, 4 bounces), for every one of them or for one card: another
// GPU or other settings measure, but are not judged.
#pragma once

#include <cuda_runtime.h>

#include <cstdio>
#include <functional>
#include <string>

#include <scene_view.h>

struct SpeedTarget {
    const char* config;        // the benchmark configuration it judges
    double max_ms;             // its best kernel time must be at most this (0: no such bar)
    const char* faster_than;   // or, when set, below this configuration's best time
    const char* gpu = nullptr;  // the card it is set for (in its name); null: every target GPU
};

// The GPUs the bars are set on (in their names): the cards the course may get.
constexpr const char* kTargetGpus[] = {"H100", "H200"};

// The target GPU a name holds, or "" for another GPU.
inline std::string target_gpu_of(const std::string& name) {
    for (const char* gpu : kTargetGpus)
        if (name.find(gpu) != std::string::npos) return gpu;
    return "";
}

// Lab 05's bars (lab05-bench's configurations): the reference as lab05-ref renders the
// baseline, with the kernel for the scene's own primitives (the walls as axis-aligned
// rectangles), on each card as fast as the best megakernel known to keep IEEE division and
// square root (measured outside the course on both cards), and "general", the same walls as
// convex quads with the kernel for every kind but rectangles: the speed of a scene whose walls
// are not aligned with the axes.
constexpr SpeedTarget kLab05Targets[] = {{"reference", 17.2, nullptr, "H100"},
                                         {"reference", 17.0, nullptr, "H200"},
                                         {"general", 18.0, nullptr}};

// Why this run is not the one the bars are set for, or "" when it is.
inline std::string why_not_judged(const cudaDeviceProp& prop, const std::string& scene_path,
                                  const RenderSettings& s) {
    if (target_gpu_of(prop.name).empty()) {
        return std::string("the bars are set on an NVIDIA H100 and an NVIDIA H200, not this ") +
               prop.name;
    }
    const std::string baseline = "common/scenes/cornell.json";
    const bool cornell =
        scene_path.size() >= baseline.size() &&
        scene_path.compare(scene_path.size() - baseline.size(), baseline.size(), baseline) == 0;
    if (!cornell || s.width != 600 || s.height != 600 || s.spp != 512 || s.bounces != 4) {
        return "the bars are set for the baseline: common/scenes/cornell.json, 600x600, 512 spp, "
               "4 bounces";
    }
    return "";
}

// The JSON array of the targets for the GPU named `gpu_name` (a bar set for another card is
// left out; for a GPU that is no target, every bar, not judged): each with its bar, the best
// time measured (null when the configuration was not run: best_ms returns a negative number)
// and "met" (true, false, or null when not judged, `why_not` saying why).
template <size_t N>
std::string targets_json(const SpeedTarget (&targets)[N],
                         const std::function<double(const char*)>& best_ms,
                         const std::string& why_not, const std::string& gpu_name) {
    const std::string card = target_gpu_of(gpu_name);
    std::string out = "[";
    char buffer[512];
    bool first = true;
    for (size_t i = 0; i < N; ++i) {
        const SpeedTarget& t = targets[i];
        if (t.gpu && !card.empty() && card != t.gpu) continue;
        const std::string on = t.gpu ? t.gpu : card.empty() ? "H100 or H200" : card;
        const double ms = best_ms(t.config);
        const double other = t.faster_than ? best_ms(t.faster_than) : 0.0;
        const bool measured = ms >= 0 && other >= 0;
        char bar[64];
        if (t.faster_than) std::snprintf(bar, sizeof bar, "faster than %s", t.faster_than);
        else std::snprintf(bar, sizeof bar, "at most %g ms", t.max_ms);
        const bool met = t.faster_than ? ms < other : ms <= t.max_ms;
        const char* verdict = !measured || !why_not.empty() ? "null" : met ? "true" : "false";
        std::snprintf(buffer, sizeof buffer,
                      "%s{\"config\": \"%s\", \"bar\": \"%s on an NVIDIA %s, the baseline\", ",
                      first ? "" : ", ", t.config, bar, on.c_str());
        first = false;
        out += buffer;
        if (measured) std::snprintf(buffer, sizeof buffer, "\"best_ms\": %.3f, ", ms);
        else std::snprintf(buffer, sizeof buffer, "\"best_ms\": null, ");
        out += buffer;
        out += std::string("\"met\": ") + verdict;
        if (!measured) out += ", \"why_not\": \"not run in this call\"";
        else if (!why_not.empty()) out += ", \"why_not\": \"" + why_not + "\"";
        out += "}";
    }
    return out + "]";
}
