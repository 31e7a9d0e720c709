// A probe for the handout (built as lab03-row-costs): lab 01's serial render, timing every
// row. It prints one extra line to stderr, "row-seconds: t0 t1 ...", the render time of each
// row, top first; tools/bench/openmp.py turns it into the cost profile and predicts how
// well each loop schedule balances those rows. The image is lab 01's, bit for bit.
#include <cstdio>
#include <string>
#include <vector>

#include "lab.h"
#include "pixel_renderer.h"
#include "timer.h"

const char* const kLabName = "03-openmp-row-costs";

RenderStats render(const RenderJob& job, Image& image) {
    const PixelRenderer pixel(job);
    std::vector<double> row_seconds(job.settings.height);
    const Timer timer;
    for (int y = 0; y < job.settings.height; ++y) {
        const Timer row;
        for (int x = 0; x < job.settings.width; ++x) image.at(x, y) = pixel(x, y);
        row_seconds[y] = row.seconds();
        job.progress.rows_done();
    }
    const double seconds = timer.seconds();
    std::string line = "row-seconds:";
    for (double t : row_seconds) line += " " + std::to_string(t);
    std::fprintf(stderr, "%s\n", line.c_str());
    return {seconds, cpu_model_name() + ", 1 thread"};
}
