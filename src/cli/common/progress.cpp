// ProgressLine (progress.h).
#include "cli/common/progress.h"

#include <algorithm>
#include <cmath>
#include <unistd.h>

#include <fmt/format.h>

namespace octiso::cli {

ProgressLine ProgressLine::on_stderr(bool wanted, double delay_s) {
    return ProgressLine(stderr, wanted && ::isatty(STDERR_FILENO), delay_s);
}

ProgressLine::ProgressLine(std::FILE* out, bool enabled, double delay_s)
    : out_(out), enabled_(enabled), delay_s_(delay_s), start_(Clock::now()), last_(start_) {}

ProgressLine::ProgressLine(ProgressLine&& o) noexcept
    : out_(o.out_), enabled_(o.enabled_), delay_s_(o.delay_s_), shown_(o.shown_), start_(o.start_), last_(o.last_) {
    o.enabled_ = o.shown_ = false;
}

std::string ProgressLine::text(double done, double total, double elapsed_s, const std::string& detail) {
    const double f = total > 0 ? std::clamp(done / total, 0.0, 1.0) : 0.0;
    constexpr int kWidth = 24;
    const int filled = int(f * kWidth);
    std::string line = "[" + std::string(size_t(filled), '#') + std::string(size_t(kWidth - filled), ' ') + "] ";
    line += fmt::format("{:3.0f}%", f * 100);
    if (!detail.empty()) line += "  " + detail;
    if (f > 0 && f < 1) line += fmt::format("  ETA {:.0f} s", std::ceil(elapsed_s * (1 - f) / f));
    else if (f >= 1) line += fmt::format("  {:.1f} s", elapsed_s);
    return line;
}

void ProgressLine::update(double done, double total, const std::string& detail) {
    if (!enabled_) return;
    const Clock::time_point now = Clock::now();
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const bool last = done >= total;
    if (elapsed < delay_s_ && !shown_) return;
    if (shown_ && !last && std::chrono::duration<double>(now - last_).count() < 0.25) return;
    last_ = now;
    shown_ = true;
    // Padding clears what a longer line drawn before left behind.
    std::fprintf(out_, "\r%-78s", text(done, total, elapsed, detail).c_str());
    std::fflush(out_);
}

void ProgressLine::finish() {
    if (shown_) {
        std::fputc('\n', out_);
        std::fflush(out_);
    }
    shown_ = false;
}

}  // namespace octiso::cli
