// A GPU benchmark's main(): whatever goes wrong (bad flags or scene, no GPU, a GPU fault,
// memory exhausted, anything else thrown) ends as one "error: ..." line on stderr and a
// non-zero exit status, as the lab binaries end (common/host/lab_main.cpp), never an abort.
// Bad input is found before a benchmark prints anything; a GPU fault part-way through leaves
// on stdout the JSON of what was measured before it, which the error line and the status
// mark as incomplete.
#pragma once

#include <cstdio>
#include <exception>
#include <new>

#include <errors.h>

inline int bench_main(int (*run)(int, char**), int argc, char** argv) {
    const auto fail = [](const char* message, int status) {
        std::fflush(stdout);
        std::fprintf(stderr, "error: %s\n", message);
        return status;
    };
    try {
        return run(argc, argv);
    } catch (const InputError& e) {
        return fail(e.what(), kExitBadInput);
    } catch (const DeviceError& e) {
        return fail(e.what(), kExitDeviceError);
    } catch (const std::bad_alloc&) {
        return fail("out of memory (is the image size or spp absurd?)", kExitBadInput);
    } catch (const std::exception& e) {
        return fail(e.what(), 1);
    } catch (...) {
        return fail("an unknown exception", 1);
    }
}
