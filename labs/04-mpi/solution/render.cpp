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
void dynamic_master(const PixelRenderer& pixel, const Team& team, Image& image, Progress& progress,
                    RankReport& report) {
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
void dynamic_worker(const PixelRenderer& pixel, const Team& team, Image& image, Progress& progress,
                    RankReport& report) {
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
