// Progress display on stderr, for a terminal only. Thread-safe: render threads report
// finished rows; whoever crosses the next redraw time redraws.
#pragma once

#include <atomic>
#include <chrono>

class Progress {
public:
    // Shows a bar when `enabled` (stderr is a terminal and not --quiet); else does nothing.
    Progress(long total_rows, bool enabled);
    ~Progress() { finish(); }

    void rows_done(long n = 1);  // report finished work; cheap when disabled or throttled
    void finish();               // final redraw and end of line, if a bar was drawn

private:
    void draw(long done);

    long total_;
    bool enabled_;
    std::atomic<long> done_{0};
    std::atomic<long long> next_draw_ns_{0};  // steady-clock time of the next redraw
    std::chrono::steady_clock::time_point start_;
    std::atomic<bool> drawn_{false};  // a bar is on screen
};

// Whether a progress bar should be shown: stderr is a terminal and the user did not ask
// for quiet.
bool progress_wanted(bool quiet);
