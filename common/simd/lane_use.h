// How full a renderer's packets are, bounce by bounce: what lab02-bench prints with
// RT_SIMD_LANE_USE=1 (handouts/02-simd.md, section 8). Plain data, no intrinsics.
#pragma once

#include <cstdio>

struct LaneUse {
    static constexpr int kMaxBounces = 64;  // the command line's limit
    double packets[kMaxBounces] = {};       // packets traced at bounce b
    double paths[kMaxBounces] = {};         // lanes among them whose path was alive

    void add(int bounce, int packet_count, int path_count) {
        packets[bounce] += packet_count;
        paths[bounce] += path_count;
    }

    // One line per bounce: packets, paths, and the share of lanes that carried a path.
    void print(std::FILE* out, int lanes) const {
        std::fprintf(out, "lane use (%d lanes): bounce, packets, paths, lanes used\n", lanes);
        for (int b = 0; b < kMaxBounces && packets[b] > 0; ++b) {
            std::fprintf(out, "  %2d %12.0f %12.0f %6.1f%%\n", b, packets[b], paths[b],
                         100.0 * paths[b] / (packets[b] * lanes));
        }
    }
};
