#include <interrupt_cleanup.h>

#include <csignal>
#include <cstring>

#include <unistd.h>

namespace {

// A handler may only touch lock-free data and call async-signal-safe functions (unlink,
// signal, raise): so fixed slots of plain characters, not std::string.
constexpr int kSlots = 8;
constexpr int kMaxPath = 4096;
char g_paths[kSlots][kMaxPath];
volatile std::sig_atomic_t g_used[kSlots];
bool g_installed = false;

constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};

extern "C" void unlink_and_reraise(int signal_number) {
    for (int i = 0; i < kSlots; ++i) {
        if (g_used[i]) ::unlink(g_paths[i]);
    }
    std::signal(signal_number, SIG_DFL);
    std::raise(signal_number);
}

void install_once() {
    if (g_installed) return;
    g_installed = true;
    for (int s : kSignals) {
        // A signal that was ignored when we started (nohup, a shell's background job) stays so.
        if (std::signal(s, unlink_and_reraise) == SIG_IGN) std::signal(s, SIG_IGN);
    }
}

}  // namespace

bool remove_on_interrupt(const char* path) {
    if (std::strlen(path) >= static_cast<size_t>(kMaxPath)) return false;
    install_once();
    for (int i = 0; i < kSlots; ++i) {
        if (!g_used[i]) {
            std::strcpy(g_paths[i], path);
            g_used[i] = 1;  // after the copy: the handler never sees half a path
            return true;
        }
    }
    return false;
}

void forget_on_interrupt(const char* path) {
    for (int i = 0; i < kSlots; ++i) {
        if (g_used[i] && std::strcmp(g_paths[i], path) == 0) g_used[i] = 0;
    }
}
