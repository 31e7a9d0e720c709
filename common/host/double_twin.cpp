#include <double_twin.h>

#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>

extern char** environ;

// Defined by double_twin.S in a reference's twin object; null in every other binary.
extern "C" {
extern const unsigned char rt_double_twin_begin[] __attribute__((weak));
extern const unsigned char rt_double_twin_end[] __attribute__((weak));
}

// The twin's size in bytes (two symbols of one section: compared as addresses).
static size_t twin_size() {
    if (rt_double_twin_begin == nullptr) return 0;
    return reinterpret_cast<uintptr_t>(rt_double_twin_end) -
           reinterpret_cast<uintptr_t>(rt_double_twin_begin);
}

bool has_double_twin() { return twin_size() > 0; }

// The twin runs from an anonymous memory file: nothing is written where the binary lies (a
// release's read-only folder, a sandbox), and nothing is left behind.
const char* run_double_twin(char** argv) {
    if (!has_double_twin()) return "this binary carries no double build";
    if (const char* staged = std::getenv("RT_DOUBLE_TWIN"); staged != nullptr && *staged) {
        execve(staged, argv, environ);
        return std::strerror(errno);
    }
    const int fd = memfd_create("double-build", MFD_CLOEXEC);
    if (fd < 0) return std::strerror(errno);
    const unsigned char* p = rt_double_twin_begin;
    size_t left = twin_size();
    while (left > 0) {
        const ssize_t n = write(fd, p, left);
        if (n <= 0) {
            const int error = errno;
            close(fd);
            return std::strerror(error);
        }
        p += n;
        left -= static_cast<size_t>(n);
    }
    fexecve(fd, argv, environ);
    const int error = errno;
    close(fd);
    return std::strerror(error);
}
