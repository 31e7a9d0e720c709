#include <progress.h>

#include <unistd.h>

#include <cstdio>

bool progress_wanted(bool quiet) { return !quiet && isatty(STDERR_FILENO); }

Progress::Progress(long total_rows, bool enabled)
    : total_(total_rows > 0 ? total_rows : 1),
      enabled_(enabled),
      start_(std::chrono::steady_clock::now()) {}

void Progress::finish() {
    if (drawn_.exchange(false)) {
        draw(done_.load());
        std::fputc('\n', stderr);
    }
}

void Progress::rows_done(long n) {
    const long done = done_.fetch_add(n, std::memory_order_relaxed) + n;
    if (!enabled_) return;
    const long long now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                              std::chrono::steady_clock::now() - start_)
                              .count();
    long long due = next_draw_ns_.load(std::memory_order_relaxed);
    if (now < due) return;
    // One thread wins the redraw; ten redraws a second is plenty.
    if (next_draw_ns_.compare_exchange_strong(due, now + 100'000'000)) {
        drawn_ = true;
        draw(done);
    }
}

void Progress::draw(long done) {
    const double fraction = static_cast<double>(done) / total_;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const int width = 40;
    const int filled = static_cast<int>(fraction * width);
    char bar[width + 1];
    for (int i = 0; i < width; ++i) bar[i] = i < filled ? '#' : '.';
    bar[width] = '\0';
    const double eta = fraction > 0 ? elapsed * (1 - fraction) / fraction : 0;
    std::fprintf(stderr, "\r[%s] %5.1f%%  %6.1f s elapsed, ~%.1f s left ", bar, 100.0 * fraction,
                 elapsed, eta);
    std::fflush(stderr);
}
