// RenderProgress and render_in_batches (render_progress.h).
#include "cli/render_progress.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <vector>

namespace octiso::cli {

RenderStats render_in_batches(const Renderer& renderer, const Camera& camera, Frame& frame,
                              const std::function<void(int, int)>& after_batch, int first_batch, double batch_seconds) {
    renderer.prepare_frame(camera, frame);
    const int count = renderer.tile_grid(camera.width, camera.height).count();
    std::vector<int> tiles(static_cast<size_t>(count));
    std::iota(tiles.begin(), tiles.end(), 0);
    RenderStats total;
    int done = 0, batch = std::max(1, first_batch);
    while (done < count) {
        const int n = std::min(batch, count - done);
        const RenderStats s = renderer.render_tiles(camera, std::span<const int>(tiles).subspan(size_t(done), size_t(n)), frame);
        total.seconds += s.seconds, total.busy_seconds += s.busy_seconds, total.rays += s.rays, total.hits += s.hits;
        for (size_t k = 0; k < s.hits_by_cell_log2.size(); ++k) total.hits_by_cell_log2[k] += s.hits_by_cell_log2[k];
        total.threads = std::max(total.threads, s.threads);
        done += n;
        after_batch(done, count);
        // The next batch takes about batch_seconds at the rate so far: few barriers per second
        // (each one idles the threads that finish their tiles first). scripts/flag_cost.py --flag=--progress,
        // ch2better --iso 80.5, 8 interleaved pairs: 2048^2 on 2 threads 1.7026 s with batches
        // against 1.7054 s without (median frame), 1536^2 on 1 thread 1.0129 against 1.0068:
        // within noise (BENCHMARKS.md, "Progress inside a frame").
        const double rate = total.seconds > 0 ? double(done) / total.seconds : 0;
        batch = rate > 0 ? int(std::clamp(rate * batch_seconds, 1.0, double(count))) : 2 * batch;
    }
    frame.stats = total;
    return total;
}

RenderProgress::RenderProgress(bool wanted, bool forced, size_t frames, int spp)
    : line_(stderr, forced || (wanted && ::isatty(STDERR_FILENO)), frames > 1 || forced ? 0.0 : 1.0), frames_(frames), spp_(spp) {}

void RenderProgress::draw(double sample_fraction, const std::string& what) {
    const double total = double(frames_) * spp_;
    std::string detail;
    if (frames_ > 1) detail += "frame " + std::to_string(frame_index_ + 1) + "/" + std::to_string(frames_) + ", ";
    if (spp_ > 1) detail += "sample " + std::to_string(samples_done_ % spp_ + 1) + "/" + std::to_string(spp_) + ", ";
    line_.update(double(samples_done_) + std::clamp(sample_fraction, 0.0, 1.0) * 0.999, total, detail + what);
}

RenderStats RenderProgress::trace(const Renderer& renderer, const Camera& camera, Frame& frame, size_t frame_index) {
    frame_index_ = frame_index;
    sample_start_ = ProgressLine::Clock::now();
    if (!line_.enabled()) {
        const RenderStats s = renderer.render(camera, frame);
        trace_seconds_ = s.seconds;
        return s;
    }
    const RenderStats s = render_in_batches(renderer, camera, frame, [&](int done, int count) {
        draw(trace_share_ * done / count, "tiles " + std::to_string(done) + "/" + std::to_string(count));
    });
    trace_seconds_ = std::chrono::duration<double>(ProgressLine::Clock::now() - sample_start_).count();
    return s;
}

void RenderProgress::shading() {
    if (line_.enabled()) draw(trace_share_, "shading");
}

void RenderProgress::sample_done() {
    const double sample_seconds = std::chrono::duration<double>(ProgressLine::Clock::now() - sample_start_).count();
    if (sample_seconds > 0) trace_share_ = std::clamp(trace_seconds_ / sample_seconds, 0.0, 1.0);
    ++samples_done_;
    if (!line_.enabled()) return;
    const std::string detail = samples_done_ % spp_ != 0 ? "sample " + std::to_string(samples_done_ % spp_) + "/" + std::to_string(spp_) + " done"
                                                         : std::to_string(samples_done_ / spp_) + "/" + std::to_string(frames_) + " frames";
    line_.update(double(samples_done_), double(frames_) * spp_, detail);
}

}  // namespace octiso::cli
