// Lab 04's plumbing around the exercise: who this rank is, which distribution rank 0 chose,
// what each rank did (RT_MPI_REPORT) and how the run is described. Not student code: the
// exercise is solution/render.cpp (skeleton/render.cpp), which uses these.
#pragma once

#include <string>
#include <vector>

enum class Distribution { block, interleaved, dynamic };
const char* const kDistributionNames[] = {"block", "interleaved", "dynamic"};

// The default, measured (handouts/04-mpi.md, section 9): dynamic ties at 2 ranks and is the
// fastest at 8 and 16 (16-core Xeon, 8 ranks: 7.32x, against 7.09x interleaved and 6.57x
// block). Blocks suffer from the unequal cost of the bands (busiest / mean 1.12 at 8 bands);
// interleaved rows balance the work (1.003) but not the time when cores run at unequal
// speeds (other load, other hosts, a VM's neighbours), which dynamic absorbs. Its price, two
// small messages per row, is far below a row's thousands of paths.
constexpr Distribution kDefaultDistribution = Distribution::dynamic;

// This process among the others.
struct Team {
    int rank = 0;     // 0..size-1; rank 0 assembles the image
    int size = 1;     // number of ranks
    int threads = 1;  // OpenMP threads inside each rank
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

// CPU time of this process so far (all its threads).
double process_cpu_seconds();

// Rank 0's choice of distribution and report, told to every rank: mpirun does not pass the
// environment to other hosts unless asked to (-x), and the ranks must agree.
struct RunConfig {
    Distribution distribution = kDefaultDistribution;
    bool report = false;  // RT_MPI_REPORT set (and not 0)
};

// Reads RT_MPI_DISTRIBUTION and RT_MPI_REPORT on rank 0 and tells every rank. Throws
// InputError on every rank alike for an unknown distribution.
RunConfig run_config(const Team& team);

// How many hosts the ranks run on (ranks that can share memory count as one host).
int host_count();

// RT_MPI_REPORT: every rank's rows and busy time, printed by rank 0 on stderr. Collective.
void print_report(const Team& team, const RankReport& mine, double seconds);

// The run's RenderStats::device: CPU, ranks, hosts, threads and distribution.
std::string describe_run(const Team& team, int hosts, Distribution distribution);
