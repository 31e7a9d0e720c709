#include "mpi_run.h"

#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>

#include <errors.h>
#include <lab.h>

double process_cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

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
                                     "dynamic, found '") +
                         (name ? name : "") + "'");
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
static std::string row_ranges(std::vector<int> rows) {
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

std::string describe_run(const Team& team, int hosts, Distribution distribution) {
    const auto plural = [](int n, const char* what) {
        return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
    };
    std::string device = cpu_model_name() + ", " + plural(team.size, "rank");
    if (hosts > 1) device += " on " + plural(hosts, "host");
    return device + " x " + plural(team.threads, "thread") + ", " +
           kDistributionNames[static_cast<int>(distribution)];
}
