// Lab 04: your copy, yours to edit. Every place to fill in is marked TODO(lab04).
// Lab 04: lab 01's image, rendered by several MPI ranks: processes, possibly on different
// hosts, that share nothing and talk only by messages.
//
// Every rank loads the scene and renders the rows it is given; rank 0 assembles the image
// and the shared driver writes it there (labs/04-mpi/mpi_main.cpp says which rank writes).
// Each pixel is lab 01's render_pixel (through PixelRenderer), and its random numbers depend
// only on (seed, pixel, sample, dimension), so the image is lab 01's, bit for bit, for any
// number of ranks and threads and any distribution.
//
// RT_MPI_DISTRIBUTION picks how the rows are shared, so one binary with the shared command
// line measures all three (only rank 0's environment counts):
//   block        rank r renders one contiguous band of rows (the report's design)
//   interleaved  rank r renders rows r, r + n, r + 2n, ... (n ranks)
//   dynamic      rank 0 hands out rows on demand and renders rows itself in between
// --threads T runs T OpenMP threads inside each rank (hybrid MPI + OpenMP); the default is 1,
// one rank per core being what mpirun starts. RT_MPI_REPORT=1 prints on stderr what each rank
// rendered and how long it was busy: the load balance, measured.
#include <mpi.h>
#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

#include "errors.h"
#include "lab.h"
#include "mpi_run.h"
#include "pixel_renderer.h"
#include "timer.h"

#if defined(RT_USE_SIMD)
// Built so (lab04-simd-ref), each pixel uses lab 02's AVX2 geometry. This file is then built
// with AVX2, so it may not run before the CPU is checked: labs/04-mpi/simd_entry.cpp (built
// without AVX2) defines render(), checks every rank's CPU, then calls this one.
const char* const kLabName = "04-mpi-simd";
#define render render_avx2
#else
const char* const kLabName = "04-mpi";
#endif

namespace {

static_assert(sizeof(Vec3) == 3 * sizeof(float), "a pixel travels as 3 MPI_FLOATs");

// Dynamic distribution: the work unit is one row per thread (600 units at the baseline with
// one thread: enough to balance, few enough that messages cost nothing; with T threads, T
// rows keep them all busy). A worker holds kPrefetch units at a time, so it never waits for
// rank 0, which answers only between the units it renders itself.
constexpr int kChunkRows = 1;
constexpr int kPrefetch = 3;
constexpr int kTagWork = 1;    // rank 0 -> worker: {first row, row count}; count 0: stop
constexpr int kTagResult = 2;  // worker -> rank 0: those rows' pixels, in order

// Rows [begin, end) of the image.
struct RowRange {
    int begin = 0;
    int end = 0;
    int count() const { return end - begin; }
};

// Renders the given image rows (any order) into `out`, row after row, with the team's threads.
void render_rows(const PixelRenderer& pixel, const std::vector<int>& rows, int width,
                 const Team& team, Vec3* out, RankReport& report) {
    const Timer timer;
    const double cpu_start = process_cpu_seconds();
    const long pixels = static_cast<long>(rows.size()) * width;
    // TODO(lab04): hybrid MPI + OpenMP: share these pixels among team.threads threads.
    // Until then: one thread per rank, whatever --threads says.
    (void)team;
    for (long i = 0; i < pixels; ++i) {
        out[i] = pixel(static_cast<int>(i % width), rows[i / width]);
    }
    report.times.rows += static_cast<double>(rows.size());
    report.times.busy_seconds += timer.seconds();
    report.times.cpu_seconds += process_cpu_seconds() - cpu_start;
    report.rows.insert(report.rows.end(), rows.begin(), rows.end());
}

// The contiguous band of rows of `rank` among `ranks`: the report's distribution. Bands differ
// by at most one row; with more ranks than rows, some bands are empty.
RowRange block_rows(int height, int rank, int ranks) {
    return {static_cast<int>(static_cast<long>(height) * rank / ranks),
            static_cast<int>(static_cast<long>(height) * (rank + 1) / ranks)};
}

// The rows `rank` renders under a static distribution, in the order they travel to rank 0.
std::vector<int> static_rows(Distribution distribution, int height, int rank, int ranks) {
    std::vector<int> rows;
    // TODO(lab04): Distribution::interleaved: rank r renders rows r, r + ranks,
    // r + 2 * ranks, ... Until then every distribution is contiguous blocks.
    (void)distribution;
    const RowRange band = block_rows(height, rank, ranks);
    for (int y = band.begin; y < band.end; ++y) rows.push_back(y);
    return rows;
}

// Block and interleaved: every rank renders its rows into a buffer of its own, then rank 0
// collects all the buffers and puts each row in its place.
void render_static(Distribution distribution, const PixelRenderer& pixel, const Team& team,
                   Image& image, Progress& progress, RankReport& report) {
    const int width = image.width;
    const std::vector<int> mine = static_rows(distribution, image.height, team.rank, team.size);
    std::vector<Vec3> buffer(mine.size() * width);
    render_rows(pixel, mine, width, team, buffer.data(), report);
    progress.rows_done(static_cast<long>(mine.size()));
    // TODO(lab04): gather every rank's rows on rank 0 (MPI_Gatherv: the pieces differ in
    // size) and put each row in its place. Until then rank 0 keeps only its own rows: the
    // other ranks' work is lost, and their part of the image stays black.
    if (team.rank != 0) return;
    for (size_t i = 0; i < mine.size(); ++i)
        std::copy_n(&buffer[i * width], width, &image.at(0, mine[i]));
}

// Dynamic, rank 0: the master. It hands rows to the workers as they finish earlier ones and
// renders rows itself in between, collecting results after each unit of its own. With one
// rank it simply renders everything.
void dynamic_master(const PixelRenderer& pixel, const Team& team, Image& image, Progress& progress,
                    RankReport& report) {
    // TODO(lab04): the dynamic master-worker distribution (see the handout). Until then:
    // contiguous blocks.
    render_static(Distribution::block, pixel, team, image, progress, report);
}

// Dynamic, ranks 1...: a worker. It renders the rows it is given and sends them back, until
// told to stop.
void dynamic_worker(const PixelRenderer& pixel, const Team& team, Image& image, Progress& progress,
                    RankReport& report) {
    // TODO(lab04): the dynamic master-worker distribution (see the handout). Until then:
    // contiguous blocks.
    render_static(Distribution::block, pixel, team, image, progress, report);
}

}  // namespace

RenderStats render(const RenderJob& job, Image& image) {
    Team team;
    MPI_Comm_rank(MPI_COMM_WORLD, &team.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &team.size);
    team.threads = job.threads > 0 ? job.threads : 1;
    const RunConfig config = run_config(team);  // throws on every rank alike
    const int hosts = host_count();
    const PixelRenderer pixel(job);
    RankReport report;

    // The clock starts when every rank is ready (MPI_Init and the scene loading are behind
    // us) and stops when the image is complete on rank 0.
    MPI_Barrier(MPI_COMM_WORLD);
    const Timer timer;
    switch (config.distribution) {
        case Distribution::block:
        case Distribution::interleaved:
            render_static(config.distribution, pixel, team, image, job.progress, report);
            break;
        case Distribution::dynamic:
            if (team.rank == 0) {
                dynamic_master(pixel, team, image, job.progress, report);
            } else {
                dynamic_worker(pixel, team, image, job.progress, report);
            }
            break;
    }
    const double seconds = timer.seconds();
    if (config.report) print_report(team, report, seconds);
    return {seconds, describe_run(team, hosts, config.distribution)};
}
