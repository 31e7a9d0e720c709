// The running sum of one pixel's samples, kept in double.
//
// Summed in float, every add rounds at the magnitude of the sum, not of the sample: past a
// million samples each add loses a fixed part of the sample to rounding, and the mean drifts
// by about 1% (a render of the zero-variance sphere interior shows -0.9% at 2^20 spp and +1.1%
// at 2^22). In double the means at 2^12 and 2^22 spp agree to float rounding (1.2e-7
// measured). One double add per sample and channel costs nothing next to tracing the path.
#pragma once

#include <real.h>
#include <vec3.h>

struct SampleSum {
    double r = 0.0, g = 0.0, b = 0.0;  // per-channel sums of the samples added so far

    RT_HD void add(Vec3 sample) {
        r += sample.x;
        g += sample.y;
        b += sample.z;
    }

    // The mean of `count` samples, rounded once to `real`.
    RT_HD Vec3 mean(int count) const {
        return Vec3(static_cast<real>(r / count), static_cast<real>(g / count),
                    static_cast<real>(b / count));
    }
};
