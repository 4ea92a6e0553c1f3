// ViewSession: what octiso-view serves, apart from HTTP: the opened .oct file, one persistent
// Renderer per series step (built on first use and kept), the /info description (dims, value
// range, histogram, steps) and, for each frame, its pixels (PNG or raw RGBA) with its camera,
// statistics and the octiso-render command line that reproduces it. Coalescing and routes are
// server.h.
#pragma once

#include <array>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "octiso/any_octree.h"
#include "octiso/camera.h"
#include "octiso/frame.h"
#include "octiso/oct_file.h"
#include "view/request.h"

namespace octiso::view {

/// One rendered frame as the server replies it.
struct FrameReply {
    std::string body;                  ///< the pixels in the request's encoding (request.h)
    std::string content_type;          ///< image/png, or application/octet-stream for rgba
    Camera camera;
    RenderStats stats;
    double encode_seconds = 0;
    std::string command;   ///< octiso-render ... reproducing these pixels exactly (shell-quoted)
};

/// Counts of a value histogram over [lo, hi] in `counts.size()` equal bins (hi in the last).
struct Histogram {
    double lo = 0, hi = 0;
    std::vector<uint64_t> counts;
};

class ViewSession {
public:
    /// Opens `path` (OctFile::open: header and tables checked; step 0 validated here, so a bad
    /// file fails before the server starts). Throws Error(path, ...). threads: 0 = all cores.
    /// initial_iso: the isovalue the page starts at (/info "initial_iso"); none: the middle of the range.
    ViewSession(const std::string& path, int threads, std::optional<double> initial_iso = {});

    /// Renders `request` (its step's Renderer made on first use). Not thread-safe: callers
    /// serialise (the Coalescer does). Throws Error for an isovalue the file cannot render.
    FrameReply render(const FrameRequest& request);

    /// The camera of a request: orbit_camera around the data centre (camera.h).
    Camera camera_for(const FrameRequest& request) const;
    /// GET /info: one JSON object.
    const std::string& info_json() const { return info_json_; }
    uint32_t step_count() const { return file_->info().step_count; }
    const Histogram& histogram() const { return histogram_; }

private:
    std::string path_;
    int threads_;
    std::shared_ptr<const OctFile> file_;
    std::vector<std::unique_ptr<Renderer>> renderers_;   // per step, null until first used
    Frame frame_;                                        // reused: buffers kept between frames
    Histogram histogram_;
    std::string info_json_;
};

/// Step 0's stored values in `bins` bins over [range lo, hi]; decoded only when the dense array
/// is at most `max_dense_bytes` (else counts is empty: the page draws no histogram).
Histogram value_histogram(const AnyOctree& step, int bins, uint64_t max_dense_bytes);

/// The octiso-render command line for `camera` and `iso` on `path` (step `step` of a file of
/// `step_count` steps): numbers in the shortest form that reads back to the same double.
std::string render_command(const std::string& path, const Camera& camera, double iso, uint32_t step, uint32_t step_count);

}  // namespace octiso::view
