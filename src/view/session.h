// ViewSession: what octiso-view serves, apart from HTTP: the opened .oct file, one persistent
// Renderer per series step (built on first use and kept), the /info description (dims, value
// range, histogram, steps) and, for each frame, its pixels (PNG or raw RGBA) with its camera,
// statistics and the octiso-render command line that reproduces it. Every value the page sees or
// sends is a real value (CONVENTIONS 2b: a scaled NIfTI's stored * slope + inter); the session
// turns isovalues into stored ones exactly as octiso-render does. Coalescing and routes are server.h.
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
#include "octiso/look.h"
#include "octiso/oct_file.h"
#include "view/request.h"

namespace octiso::view {

/// One rendered frame as the server replies it.
struct FrameReply {
    std::string body;                  ///< the pixels in the request's encoding (request.h)
    std::string content_type;          ///< image/png, or application/octet-stream for rgba
    Camera camera;
    RenderStats stats;                 ///< the primary rays' tile loop
    LookStats look;                    ///< shadow and AO rays and the kit's shading; zero when both are off
    double encode_seconds = 0;
    std::string command;   ///< octiso-render ... reproducing these pixels exactly (shell-quoted)
};

/// Counts of a value histogram over [lo, hi] (real values) in `counts.size()` equal bins (hi in the last).
struct Histogram {
    double lo = 0, hi = 0;
    std::vector<uint64_t> counts;
};

class ViewSession {
public:
    /// Opens `path` (OctFile::open: header and tables checked; step 0 validated here, so a bad
    /// file fails before the server starts). Throws Error(path, ...). threads: 0 = all cores.
    /// initial_iso: the real isovalue the page starts at (/info "initial_iso"); none: the middle of the range.
    /// lod: level of detail of every frame (RenderOptions::lod, octiso-render --lod; 0: exact).
    ViewSession(const std::string& path, int threads, std::optional<double> initial_iso = {}, double lod = 0);

    /// Renders `request` (its step's Renderer made on first use). Not thread-safe: callers
    /// serialise (the Coalescer does). request.iso is a real value. Without shadows and AO the
    /// frame is the Renderer's own colour (octiso-render --shading headlight); with either, the
    /// depth and normal AOVs shaded by a LookShader with the light kit (octiso-render --shadows,
    /// --ao N), as octiso-render does for one sample per pixel. Throws Error("iso", ...) for an
    /// isovalue the file cannot render (outside its iso-range, named in real values).
    FrameReply render(const FrameRequest& request);

    /// The camera of a request: orbit_camera around the data centre (camera.h).
    Camera camera_for(const FrameRequest& request) const;
    /// GET /info: one JSON object.
    const std::string& info_json() const { return info_json_; }
    uint32_t step_count() const { return file_->info().step_count; }
    const Histogram& histogram() const { return histogram_; }

private:
    /// Throws Error(subject, ...) unless the real isovalue's stored value lies strictly inside the
    /// file's iso-range (when it has one); the message names the range in real values.
    void check_iso_range(double real_iso, const std::string& subject) const;

    std::string path_;
    int threads_;
    double lod_ = 0;
    std::shared_ptr<const OctFile> file_;
    ValueScale scale_;                                   // the file's stored-to-real values
    std::vector<std::unique_ptr<Renderer>> renderers_;   // per step, null until first used
    // The look of the last frame that had one, kept while its step, isovalue and look stay (a
    // LookShader holds the isovalues it was made with); remade when one of them changes.
    struct LookCache {
        uint32_t step = 0;
        double stored_iso = 0;
        bool shadows = false;
        int ao_samples = 0;
        std::optional<LookShader> shader;
    } look_;
    Frame frame_;                                        // reused: buffers kept between frames
    Histogram histogram_;
    std::string info_json_;
};

/// Step 0's values as real values (its value_scale applied) in `bins` bins over its real value
/// range, from the decoded array when it is at most `max_dense_bytes`; else from the tree
/// (value_stats: three reads of the stored step) over the voxels' exact real range, for files
/// up to 4 GiB (above, counts is empty: the page draws no histogram).
Histogram value_histogram(const AnyOctree& step, int bins, uint64_t max_dense_bytes);

/// The octiso-render command line for `camera`, the real isovalue `iso`, `look` (shadows and
/// ao_samples only; the rest at octiso-render's defaults) and level of detail `lod` (0: none) on
/// `path` (step `step` of a file of `step_count` steps): numbers in the shortest form that reads
/// back to the same double, so octiso-render converts the same real value to the same stored one.
std::string render_command(const std::string& path, const Camera& camera, double iso, const Look& look, double lod, uint32_t step,
                           uint32_t step_count);

}  // namespace octiso::view
