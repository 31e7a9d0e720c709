// GENERATED from labs/04-mpi/solution/render.cpp by tools/skeletons.py: edit this file freely,
// it is yours. (Instructors: edit the solution and run `make skeletons`.)
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

enum class Distribution { block, interleaved, dynamic };
const char* const kDistributionNames[] = {"block", "interleaved", "dynamic"};

// The default, measured (handouts/04-mpi.md, section 9): dynamic ties at 2 ranks and is the
// fastest at 8 and 16 (16-core Xeon, 8 ranks: 7.32x, against 7.09x interleaved and 6.57x
// block). Blocks suffer from the unequal cost of the bands (busiest / mean 1.12 at 8 bands);
// interleaved rows balance the work (1.003) but not the time when cores run at unequal
// speeds (other load, other hosts, a VM's neighbours), which dynamic absorbs. Its price, two
// small messages per row, is far below a row's thousands of paths.
constexpr Distribution kDefaultDistribution = Distribution::dynamic;

// Dynamic distribution: the work unit is one row per thread (600 units at the baseline with
// one thread: enough to balance, few enough that messages cost nothing; with T threads, T
// rows keep them all busy). A worker holds kPrefetch units at a time, so it never waits for
// rank 0, which answers only between the units it renders itself.
constexpr int kChunkRows = 1;
constexpr int kPrefetch = 3;
constexpr int kTagWork = 1;    // rank 0 -> worker: {first row, row count}; count 0: stop
constexpr int kTagResult = 2;  // worker -> rank 0: those rows' pixels, in order

// This process among the others.
struct Team {
    int rank = 0;     // 0..size-1; rank 0 assembles the image
    int size = 1;     // number of ranks
    int threads = 1;  // OpenMP threads inside each rank
};

// Rows [begin, end) of the image.
struct RowRange {
    int begin = 0;
    int end = 0;
    int count() const { return end - begin; }
};

// What one rank did, for RT_MPI_REPORT.
struct RankReport {
    struct Times {
        double rows = 0;          // how many rows it rendered
        double busy_seconds = 0;  // wall time inside its pixel loops
        double cpu_seconds = 0;   // CPU time of its pixel loops (all threads): the work
                                  // itself, true even when ranks share cores
    } times;                      // doubles, so one MPI_Gather collects them
    std::vector<int> rows;        // which rows, in the order rendered
};

double process_cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

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
void dynamic_master(const PixelRenderer& pixel, const Team& team, Image& image,
                    Progress& progress, RankReport& report) {
    // TODO(lab04): the dynamic master-worker distribution (see the handout). Until then:
    // contiguous blocks.
    render_static(Distribution::block, pixel, team, image, progress, report);
}

// Dynamic, ranks 1...: a worker. It renders the rows it is given and sends them back, until
// told to stop.
void dynamic_worker(const PixelRenderer& pixel, const Team& team, Image& image,
                    Progress& progress, RankReport& report) {
    // TODO(lab04): the dynamic master-worker distribution (see the handout). Until then:
    // contiguous blocks.
    render_static(Distribution::block, pixel, team, image, progress, report);
}

// Rank 0's choice of distribution and report, told to every rank: mpirun does not pass the
// environment to other hosts unless asked to (-x), and the ranks must agree.
struct RunConfig {
    Distribution distribution = kDefaultDistribution;
    bool report = false;  // RT_MPI_REPORT set (and not 0)
};

RunConfig run_config(const Team& team) {
    int choice[2] = {static_cast<int>(kDefaultDistribution), 0};  // -1: not a distribution
    const char* name = std::getenv("RT_MPI_DISTRIBUTION");
    if (team.rank == 0) {
        if (name && *name) {
            choice[0] = -1;
            for (int d = 0; d < 3; ++d) {
                if (std::string(name) == kDistributionNames[d]) choice[0] = d;
            }
        }
        const char* report = std::getenv("RT_MPI_REPORT");
        choice[1] = report && *report && std::string(report) != "0";
    }
    MPI_Bcast(choice, 2, MPI_INT, 0, MPI_COMM_WORLD);
    if (choice[0] < 0) {
        throw InputError(std::string("RT_MPI_DISTRIBUTION: expected block, interleaved or "
                                     "dynamic, found '") + (name ? name : "") + "'");
    }
    return {static_cast<Distribution>(choice[0]), choice[1] != 0};
}

// How many hosts the ranks run on (ranks that can share memory count as one host).
int host_count() {
    MPI_Comm host;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &host);
    int host_rank = 0;
    MPI_Comm_rank(host, &host_rank);
    MPI_Comm_free(&host);
    int leaders = host_rank == 0;
    MPI_Allreduce(MPI_IN_PLACE, &leaders, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    return leaders;
}

// Rows as sorted ranges, "0-2,5,7-9", at most kShown of them.
std::string row_ranges(std::vector<int> rows) {
    constexpr int kShown = 12;
    std::sort(rows.begin(), rows.end());
    std::string text;
    int shown = 0;
    for (size_t i = 0; i < rows.size();) {
        size_t j = i;
        while (j + 1 < rows.size() && rows[j + 1] == rows[j] + 1) ++j;
        if (shown++ == kShown) return text + ",...";
        if (!text.empty()) text += ",";
        text += std::to_string(rows[i]);
        if (j > i) text += "-" + std::to_string(rows[j]);
        i = j + 1;
    }
    return text.empty() ? "none" : text;
}

// RT_MPI_REPORT: every rank's rows and busy time, printed by rank 0 on stderr.
void print_report(const Team& team, const RankReport& mine, double seconds) {
    std::vector<RankReport::Times> times(team.size);
    MPI_Gather(&mine.times, 3, MPI_DOUBLE, times.data(), 3, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    std::vector<int> counts(team.size), offsets(team.size);
    for (int r = 0, offset = 0; r < team.size; ++r) {
        counts[r] = static_cast<int>(times[r].rows);
        offsets[r] = offset;
        offset += counts[r];
    }
    std::vector<int> rows(team.rank == 0 ? offsets.back() + counts.back() : 0);
    MPI_Gatherv(mine.rows.data(), static_cast<int>(mine.rows.size()), MPI_INT, rows.data(),
                counts.data(), offsets.data(), MPI_INT, 0, MPI_COMM_WORLD);
    if (team.rank != 0) return;
    double busiest = 0, total = 0;
    for (const RankReport::Times& r : times) {
        busiest = std::max(busiest, r.cpu_seconds);
        total += r.cpu_seconds;
    }
    for (int r = 0; r < team.size; ++r) {
        const std::vector<int> its_rows(rows.begin() + offsets[r],
                                        rows.begin() + offsets[r] + counts[r]);
        std::fprintf(stderr,
                     "rank %d: %5d rows, %8.3f s busy, %8.3f s CPU (%5.1f%% of the work): "
                     "rows %s\n",
                     r, counts[r], times[r].busy_seconds, times[r].cpu_seconds,
                     total > 0 ? 100.0 * times[r].cpu_seconds / total : 0.0,
                     row_ranges(its_rows).c_str());
    }
    std::fprintf(stderr, "render %.3f s; imbalance (busiest rank's CPU / mean): %.2f\n", seconds,
                 total > 0 ? busiest / (total / team.size) : 1.0);
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

    const auto plural = [](int n, const char* what) {
        return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
    };
    std::string device = cpu_model_name() + ", " + plural(team.size, "rank");
    if (hosts > 1) device += " on " + plural(hosts, "host");
    device += " x " + plural(team.threads, "thread") + ", " +
              kDistributionNames[static_cast<int>(config.distribution)];
    return {seconds, device};
}
