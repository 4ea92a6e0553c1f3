// octiso-render's progress over a run (issue 17 item 5): one ProgressLine for the frames of a
// series or an orbit and, inside each frame, for the tiles of each sample, so that a single frame
// above a second shows a bar and an ETA too. A sample is traced in batches of tiles through
// Renderer::render_tiles, which leaves every pixel as Renderer::render writes it (each pixel is
// traced alone), and the line is redrawn between batches; without a line the frame is one render().
// The look pass after tracing (shading, shadows, AO: octiso/look.h) is one step of the bar.
#pragma once

#include <cstddef>
#include <functional>
#include <string>

#include "cli/common/progress.h"
#include "octiso/frame.h"
#include "octiso/render.h"

namespace octiso::cli {

/// Renders `camera` into `frame` exactly as renderer.render(camera, frame) does (the same pixels
/// and frame.stats: rays and hits summed, seconds summed over the batches, threads the most used),
/// as consecutive batches of the tile grid's tiles. The first batch has `first_batch` tiles, each
/// later one as many as the rate so far traces in `batch_seconds`; after each,
/// after_batch(tiles done, tile count). Throws what Renderer::render throws.
RenderStats render_in_batches(const Renderer& renderer, const Camera& camera, Frame& frame,
                              const std::function<void(int done, int count)>& after_batch, int first_batch = 16,
                              double batch_seconds = 0.25);

class RenderProgress {
public:
    /// A line on stderr when `wanted` and stderr is a terminal, or whenever `forced`
    /// (--progress); for `frames` images of `spp` samples each. One frame waits a second
    /// before drawing (a short frame prints nothing), a series draws at once.
    RenderProgress(bool wanted, bool forced, size_t frames, int spp);

    /// One sample of frame `frame_index` (0-based, in the order rendered): render_in_batches
    /// with the line redrawn between batches, or renderer.render() when there is no line.
    RenderStats trace(const Renderer& renderer, const Camera& camera, Frame& frame, size_t frame_index);
    /// The sample's tracing is done and its shading pass starts; then sample_done() after it.
    void shading();
    void sample_done();
    /// Ends the line (if drawn) so that a report line can follow; the next update starts anew.
    void break_line() { line_.finish(); }
    bool enabled() const { return line_.enabled(); }

private:
    void draw(double sample_fraction, const std::string& what);

    ProgressLine line_;
    size_t frames_;
    int spp_;
    size_t frame_index_ = 0;
    long long samples_done_ = 0;
    // The part of a sample's time spent tracing, from the last sample (1 until one is done), so
    // that the bar and ETA stay even when a look pass (AO) costs more than the tracing.
    double trace_share_ = 1.0;
    double trace_seconds_ = 0;
    ProgressLine::Clock::time_point sample_start_;
};

}  // namespace octiso::cli
