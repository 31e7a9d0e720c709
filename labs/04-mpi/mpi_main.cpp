// Entry point of lab 04's binaries: MPI around the shared driver (common/host/lab_main.cpp).
// Every rank parses the flags, loads the scene and renders; only rank 0 opens the output
// files, writes them and prints the summary or the error line. Not a student file.
#include <mpi.h>

#include <cstdarg>
#include <cstdio>
#include <cstdlib>

#include "errors.h"
#include "lab.h"

// Ends MPI once, however the process ends: a normal return, or `--help` or `--scene-schema`,
// which exit from inside the flag parser.
static void finalize_mpi() {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
}

// MPI_ERRORS_ARE_FATAL, but the error is written to this rank's own stderr before the abort:
// OpenMPI sends its own "An error occurred in MPI_Recv ... MPI_ERR_TRUNCATE" text to mpirun as
// a message, which now and then arrives cut short when the rank aborts at once (mpirun then
// prints only "ORTE_ERROR_LOG: ... show_help.c"), and the student is left without the cause.
// OpenMPI passes the failing call's name after the two standard arguments.
static void report_and_abort(MPI_Comm* comm, int* code, ...) {
    char text[MPI_MAX_ERROR_STRING] = "";
    int length = 0;
    MPI_Error_string(*code, text, &length);
    const char* call = "an MPI call";
#ifdef OPEN_MPI
    va_list more;
    va_start(more, code);
    const char* name = va_arg(more, const char*);
    va_end(more);
    if (name != nullptr) call = name;
#endif
    int rank = -1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    std::fprintf(stderr, "rank %d: An error occurred in %s: %s\n", rank, call, text);
    std::fflush(stderr);
    MPI_Abort(*comm, *code);
}

int main(int argc, char** argv) {
    // FUNNELED: OpenMP threads render inside a rank, but only the main thread calls MPI.
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    std::atexit(finalize_mpi);
    MPI_Errhandler fatal_with_cause;
    MPI_Comm_create_errhandler(report_and_abort, &fatal_with_cause);
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, fatal_with_cause);
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    // Rank 0 speaks for everyone; the driver keeps the others quiet, and this keeps `--help`
    // and `--scene-schema` from printing once per rank.
    if (rank != 0 && !std::freopen("/dev/null", "w", stdout)) return 1;

    LabHooks hooks;
    hooks.writes_output = rank == 0;
    // Before rendering, the ranks agree that every one of them is ready: a rank that failed
    // (a bad flag, a scene file missing on its host, an unwritable --out on rank 0) would
    // otherwise leave the others waiting for it forever.
    hooks.setup_done = [](bool setup_ok) {
        int all_ok = setup_ok;
        MPI_Allreduce(MPI_IN_PLACE, &all_ok, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
        if (setup_ok && !all_ok) {
            throw InputError(
                "another MPI rank could not set up the render (on several hosts: "
                "is the scene file at the same path on each?)");
        }
    };
    const int status = lab_main(argc, argv, hooks);
    finalize_mpi();
    return status;
}
