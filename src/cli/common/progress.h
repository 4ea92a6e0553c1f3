// ProgressLine: the one progress display of the tools (issue 17 item 5): a bar, done/total, a
// detail the caller chooses and an ETA, redrawn in place on stderr. TTY-aware: nothing at all is
// written when stderr is not a terminal (logs, pipes, tests), so reports stay line-oriented.
// octiso-convert (slabs read, steps built) and octiso-render (frames, and tiles inside a frame:
// cli/render_progress.h) use it.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>

namespace octiso::cli {

class ProgressLine {
public:
    using Clock = std::chrono::steady_clock;
    /// On stderr, shown only if `wanted` and stderr is a terminal, and only once the operation has
    /// run for `delay_s` seconds (short operations print nothing).
    static ProgressLine on_stderr(bool wanted, double delay_s = 1.0);
    /// On `out` when `enabled` (tests pass a temporary file).
    ProgressLine(std::FILE* out, bool enabled, double delay_s);
    ~ProgressLine() { finish(); }
    ProgressLine(ProgressLine&& other) noexcept;
    ProgressLine(const ProgressLine&) = delete;
    ProgressLine& operator=(const ProgressLine&) = delete;

    /// `done` of `total` units (total > 0) and a detail ("3.2 Mvoxel/s"); redrawn at most 4 times a
    /// second, and always when done reaches total. The ETA assumes the rate so far.
    void update(double done, double total, const std::string& detail = "");
    /// Ends the line if anything was drawn, so that the next message starts on a line of its own.
    void finish();
    bool shown() const { return shown_; }
    bool enabled() const { return enabled_; }

    /// The line drawn for `done` of `total` after `elapsed_s` seconds (without the leading \r).
    static std::string text(double done, double total, double elapsed_s, const std::string& detail);

private:
    std::FILE* out_;
    bool enabled_;
    double delay_s_;
    bool shown_ = false;
    Clock::time_point start_, last_;
};

}  // namespace octiso::cli
