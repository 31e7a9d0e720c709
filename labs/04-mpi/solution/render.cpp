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
    // BEGIN SOLUTION
    // Hybrid: the rank's OpenMP threads share its pixels. Pixels rather than rows, because
    // the dynamic master renders one row at a time and that row must keep every thread busy;
    // 16 pixels are thousands of paths, so handing them out costs nothing measurable.
#pragma omp parallel for schedule(dynamic, 16) num_threads(team.threads)
    for (long i = 0; i < pixels; ++i) {
        out[i] = pixel(static_cast<int>(i % width), rows[i / width]);
    }
    // SKELETON
    //> // TODO(lab04): hybrid MPI + OpenMP: share these pixels among team.threads threads.
    //> // Until then: one thread per rank, whatever --threads says.
    //> (void)team;
    //> for (long i = 0; i < pixels; ++i) {
    //>     out[i] = pixel(static_cast<int>(i % width), rows[i / width]);
    //> }
    // END SOLUTION
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
    // BEGIN SOLUTION
    if (distribution == Distribution::interleaved) {
        for (int y = rank; y < height; y += ranks) rows.push_back(y);
        return rows;
    }
    // SKELETON
    //> // TODO(lab04): Distribution::interleaved: rank r renders rows r, r + ranks,
    //> // r + 2 * ranks, ... Until then every distribution is contiguous blocks.
    //> (void)distribution;
    // END SOLUTION
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
    // BEGIN SOLUTION
    // One MPI_Gatherv: the pieces differ in size (bands by one row, and empty ones when there
    // are more ranks than rows), so each rank's count and offset are given, in floats.
    std::vector<int> counts(team.size), offsets(team.size);
    for (int r = 0, offset = 0; r < team.size; ++r) {
        const auto rows = static_rows(distribution, image.height, r, team.size);
        counts[r] = static_cast<int>(rows.size()) * 3 * width;
        offsets[r] = offset;
        offset += counts[r];
    }
    std::vector<Vec3> gathered(team.rank == 0 ? image.pixels.size() : 0);
    MPI_Gatherv(buffer.data(), counts[team.rank], MPI_FLOAT, gathered.data(), counts.data(),
                offsets.data(), MPI_FLOAT, 0, MPI_COMM_WORLD);
    if (team.rank != 0) return;
    // `gathered` holds rank 0's rows, then rank 1's, ...: each goes where it belongs. (For
    // blocks that is where it already is; one path for both keeps the code short, and the
    // copy costs a millisecond.)
    const Vec3* next = gathered.data();
    for (int r = 0; r < team.size; ++r) {
        for (int y : static_rows(distribution, image.height, r, team.size)) {
            std::copy_n(next, width, &image.at(0, y));
            next += width;
        }
    }
    progress.rows_done(image.height - static_cast<long>(mine.size()));
    // SKELETON
    //> // TODO(lab04): gather every rank's rows on rank 0 (MPI_Gatherv: the pieces differ in
    //> // size) and put each row in its place. Until then rank 0 keeps only its own rows: the
    //> // other ranks' work is lost, and their part of the image stays black.
    //> if (team.rank != 0) return;
    //> for (size_t i = 0; i < mine.size(); ++i)
    //>     std::copy_n(&buffer[i * width], width, &image.at(0, mine[i]));
    // END SOLUTION
}

// Dynamic, rank 0: the master. It hands rows to the workers as they finish earlier ones and
// renders rows itself in between, collecting results after each unit of its own. With one
// rank it simply renders everything.
void dynamic_master(const PixelRenderer& pixel, const Team& team, Image& image,
                    Progress& progress, RankReport& report) {
    // BEGIN SOLUTION
    const int width = image.width;
    const int height = image.height;
    // Rows handed out at a time. Alone, rank 0 has nobody to serve: all rows at once, one
    // parallel loop, and its threads never wait for each other at the end of a unit.
    const int unit = team.size == 1 ? height : kChunkRows * team.threads;
    int next_row = 0;   // the first row nobody has been given
    int rows_done = 0;  // rows in place in the image
    // Worker w's results land in its slots w * kPrefetch ... w * kPrefetch + kPrefetch - 1:
    // a receive posted as soon as a chunk is handed out, straight into the image. Posting it
    // early matters: the result can then arrive while rank 0 is busy rendering its own row.
    const int slots = team.size * kPrefetch;
    std::vector<MPI_Request> receives(slots, MPI_REQUEST_NULL);
    std::vector<RowRange> slot_rows(slots);
    std::vector<bool> stopped(team.size, false);

    // The next `unit` rows nobody has been given (none at the end).
    const auto take = [&]() {
        const RowRange chunk{next_row, std::min(height, next_row + unit)};
        next_row = chunk.end;
        return chunk;
    };
    // Gives worker w its next chunk, or tells it to stop (once) when none is left.
    const auto assign = [&](int w) {
        const RowRange chunk = take();
        if (chunk.count() == 0) {
            if (stopped[w]) return;
            stopped[w] = true;
        } else {
            int slot = w * kPrefetch;
            while (receives[slot] != MPI_REQUEST_NULL) ++slot;  // a free one: < kPrefetch busy
            slot_rows[slot] = chunk;
            MPI_Irecv(&image.at(0, chunk.begin), chunk.count() * 3 * width, MPI_FLOAT, w,
                      kTagResult, MPI_COMM_WORLD, &receives[slot]);
        }
        const int message[2] = {chunk.begin, chunk.count()};
        MPI_Send(message, 2, MPI_INT, w, kTagWork, MPI_COMM_WORLD);
    };
    // Accounts for finished results (MPI_Testsome/Waitsome's answer) and refills those workers.
    std::vector<int> finished(slots);
    const auto collect = [&](int count) {
        if (count == MPI_UNDEFINED) return;  // no receive was pending (no workers)
        for (int i = 0; i < count; ++i) {
            const int slot = finished[i];
            rows_done += slot_rows[slot].count();
            progress.rows_done(slot_rows[slot].count());
            assign(slot / kPrefetch);
        }
    };
    // Collects everything that has arrived, without waiting. MPI_Testsome reports what was
    // complete when called and, when nothing was, makes progress (takes in arrived messages)
    // without reporting it: so call it until it finds nothing twice in a row. Calling it only
    // once per row left every result a row late and starved the workers (measured: 18% idle).
    const auto collect_arrived = [&]() {
        for (int empty = 0; empty < 2;) {
            int count = 0;
            MPI_Testsome(slots, receives.data(), &count, finished.data(), MPI_STATUSES_IGNORE);
            if (count == MPI_UNDEFINED) return;
            empty = count == 0 ? empty + 1 : 0;
            collect(count);
        }
    };

    for (int k = 0; k < kPrefetch; ++k) {
        for (int w = 1; w < team.size; ++w) assign(w);
    }
    std::vector<int> own;
    while (rows_done < height) {
        if (next_row < height) {
            const RowRange chunk = take();
            own.clear();
            for (int y = chunk.begin; y < chunk.end; ++y) own.push_back(y);
            render_rows(pixel, own, width, team, &image.at(0, chunk.begin), report);
            rows_done += chunk.count();
            progress.rows_done(chunk.count());
            collect_arrived();
        } else {  // nothing left to hand out: wait for the rows still out there
            int count = 0;
            MPI_Waitsome(slots, receives.data(), &count, finished.data(), MPI_STATUSES_IGNORE);
            collect(count);
        }
    }
    // SKELETON
    //> // TODO(lab04): the dynamic master-worker distribution (see the handout). Until then:
    //> // contiguous blocks.
    //> render_static(Distribution::block, pixel, team, image, progress, report);
    // END SOLUTION
}

// Dynamic, ranks 1...: a worker. It renders the rows it is given and sends them back, until
// told to stop.
void dynamic_worker(const PixelRenderer& pixel, const Team& team, Image& image,
                    Progress& progress, RankReport& report) {
    // BEGIN SOLUTION
    (void)progress;
    const int width = image.width;
    // kPrefetch send buffers in turn: MPI_Isend returns at once, so the worker goes on with its
    // next row while rank 0 takes this one whenever it next looks.
    std::vector<std::vector<Vec3>> buffers(kPrefetch);
    std::vector<MPI_Request> sends(kPrefetch, MPI_REQUEST_NULL);
    std::vector<int> rows;
    for (int turn = 0;; turn = (turn + 1) % kPrefetch) {
        int message[2];
        MPI_Recv(message, 2, MPI_INT, 0, kTagWork, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        if (message[1] == 0) break;
        rows.resize(message[1]);
        for (int i = 0; i < message[1]; ++i) rows[i] = message[0] + i;
        MPI_Wait(&sends[turn], MPI_STATUS_IGNORE);  // this buffer's last send is done
        buffers[turn].resize(rows.size() * width);
        render_rows(pixel, rows, width, team, buffers[turn].data(), report);
        MPI_Isend(buffers[turn].data(), static_cast<int>(rows.size()) * 3 * width, MPI_FLOAT, 0,
                  kTagResult, MPI_COMM_WORLD, &sends[turn]);
    }
    MPI_Waitall(kPrefetch, sends.data(), MPI_STATUSES_IGNORE);
    // SKELETON
    //> // TODO(lab04): the dynamic master-worker distribution (see the handout). Until then:
    //> // contiguous blocks.
    //> render_static(Distribution::block, pixel, team, image, progress, report);
    // END SOLUTION
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
