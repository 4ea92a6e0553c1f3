// ViewSession: the file, its Renderers, /info and the reproducing command line.
#include "view/session.h"

#include <charconv>
#include <chrono>
#include <cmath>
#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <cstring>

#include "octiso/error.h"
#include "octiso/render.h"
#include "octiso/volume.h"
#include "view/png.h"
#include "view/rgba.h"

namespace octiso::view {
namespace {

/// Shortest decimal that std::from_chars (octiso-render's parser) reads back to exactly `v`.
std::string exact(double v) {
    char buf[64];
    const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v);
    return ec == std::errc() ? std::string(buf, ptr) : std::string("nan");
}

std::string vec3(const std::array<double, 3>& v) { return exact(v[0]) + "," + exact(v[1]) + "," + exact(v[2]); }

/// A word the shell passes through unchanged: bare when it is plain, else single-quoted.
std::string shell_quote(const std::string& s) {
    bool plain = !s.empty();
    for (const char c : s)
        plain = plain && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                          c == '_' || c == '-' || c == '.' || c == '/' || c == ',' || c == ':' || c == '%');
    if (plain) return s;
    std::string q = "'";
    for (const char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (const unsigned char c : s) {
        if (c == '"' || c == '\\') out += '\\', out += char(c);
        else if (c < 0x20) {
            char esc[8];
            std::snprintf(esc, sizeof esc, "\\u%04x", c);
            out += esc;
        } else out += char(c);
    }
    return out + "\"";
}

std::string json_number(double v) { return std::isfinite(v) ? exact(v) : "null"; }

std::string build_info_json(const std::string& path, const OctInfo& info, const AnyOctreeInfo& step0, const Histogram& h,
                            std::optional<double> initial_iso) {
    std::string j = "{\"file\":" + json_string(path) + ",\"type\":" + json_string(std::string(scalar_type_name(info.type)));
    j += ",\"dims\":[" + std::to_string(info.dims.x) + "," + std::to_string(info.dims.y) + "," + std::to_string(info.dims.z) + "]";
    j += ",\"spacing\":[" + vec3(info.placement.spacing) + "],\"origin\":[" + vec3(info.placement.origin) + "]";
    j += ",\"steps\":" + std::to_string(info.step_count);
    auto range = [&](const std::optional<std::array<double, 2>>& r) {
        return r ? "[" + json_number((*r)[0]) + "," + json_number((*r)[1]) + "]" : std::string("null");
    };
    j += ",\"value_range\":" + range(step0.value_range) + ",\"iso_range\":" + range(info.iso_range);
    j += ",\"initial_iso\":" + (initial_iso ? json_number(*initial_iso) : std::string("null"));
    j += ",\"histogram\":{\"lo\":" + json_number(h.lo) + ",\"hi\":" + json_number(h.hi) + ",\"counts\":[";
    for (size_t i = 0; i < h.counts.size(); ++i) j += (i ? "," : "") + std::to_string(h.counts[i]);
    j += "]},\"default_azimuth\":" + exact(kDefaultAzimuthDeg) + ",\"default_elevation\":" + exact(kDefaultElevationDeg);
    j += ",\"max_side\":" + std::to_string(kMaxImageSide) + ",\"max_pixels\":" + std::to_string(kMaxImagePixels);
    j += ",\"max_elevation\":" + exact(kMaxElevationDeg) + ",\"zoom_range\":[" + exact(kMinZoom) + "," + exact(kMaxZoom) + "]}";
    return j;
}

}  // namespace

Histogram value_histogram(const AnyOctree& step, int bins, uint64_t max_dense_bytes) {
    Histogram h;
    const auto range = step.info().value_range;
    if (!range) return h;
    h.lo = (*range)[0], h.hi = (*range)[1];
    if (step.dense_bytes() > max_dense_bytes || bins <= 0) return h;
    std::vector<std::byte> dense(step.dense_bytes());
    step.decode(dense);
    h.counts.assign(size_t(bins), 0);
    const double width = h.hi - h.lo;
    dispatch_scalar_type(step.type(), [&](auto tag) {
        using T = decltype(tag);
        const size_t n = dense.size() / sizeof(T);
        for (size_t i = 0; i < n; ++i) {
            T v;
            std::memcpy(&v, dense.data() + i * sizeof(T), sizeof(T));   // no alignment assumed
            const double x = double(v);
            // value_range covers data cells only (an extent-1 border voxel can lie outside it).
            if (!(x >= h.lo && x <= h.hi)) continue;
            const double f = width > 0 ? (x - h.lo) / width * bins : 0.0;
            h.counts[std::min(size_t(bins) - 1, size_t(f))]++;
        }
    });
    return h;
}

std::string render_command(const std::string& path, const Camera& camera, double iso, uint32_t step, uint32_t step_count) {
    // The viewer shows the Renderer's own colour (headlight); octiso-render's default is the light
    // kit (deferred shading), so the command names the headlight to reproduce the frame exactly.
    std::string c = "octiso-render " + shell_quote(path) + " --iso " + exact(iso) + " --shading headlight";
    c += " --eye " + vec3(camera.eye) + " --look " + vec3(camera.look) + " --up " + vec3(camera.up);
    c += " --fov " + exact(camera.fov_deg) + " --size " + std::to_string(camera.width) + "x" + std::to_string(camera.height);
    // octiso-render renders step k of a series with --steps k:k and a name pattern.
    if (step_count > 1) c += " --steps " + std::to_string(step) + ":" + std::to_string(step) + " -o frame_%04d.png";
    else c += " -o frame.png";
    return c;
}

ViewSession::ViewSession(const std::string& path, int threads, std::optional<double> initial_iso)
    : path_(path), threads_(threads), file_(std::make_shared<const OctFile>(OctFile::open(path))) {
    if (file_->info().step_count == 0) throw Error(path, "the file has no steps");
    renderers_.resize(file_->info().step_count);
    const AnyOctree step0 = AnyOctree::step(file_, 0);   // validated now: a bad file fails before serving
    histogram_ = value_histogram(step0, 128, uint64_t(1) << 30);
    if (initial_iso) {   // refused now, not as a first frame the page cannot show
        RenderOptions options;
        options.isovalues = {*initial_iso};
        validate_options(options, step0.render_limits());
    }
    info_json_ = build_info_json(path_, file_->info(), step0.info(), histogram_, initial_iso);
}

Camera ViewSession::camera_for(const FrameRequest& r) const {
    const OctInfo& info = file_->info();
    return orbit_camera(info.dims, info.placement, r.width, r.height, r.azimuth_deg, r.elevation_deg, r.zoom);
}

FrameReply ViewSession::render(const FrameRequest& request) {
    if (request.step >= renderers_.size()) throw Error("step", "out of range");
    RenderOptions options;
    options.isovalues = {request.iso};
    options.threads = threads_;
    // The kernel directly, without Embree's dispatch: the same pixels (RenderPaths.
    // EmbreeAndDirectGiveIdenticalFrames), 1-5 % less per frame (BENCHMARKS.md, packets).
    options.use_embree = false;
    std::unique_ptr<Renderer>& renderer = renderers_[request.step];
    if (!renderer) renderer = std::make_unique<Renderer>(AnyOctree::step(file_, request.step).make_renderer(options));
    else renderer->set_options(options);   // validates the isovalue against the file's iso-range
    FrameReply reply;
    reply.camera = camera_for(request);
    reply.stats = renderer->render(reply.camera, frame_);
    const auto t0 = std::chrono::steady_clock::now();
    if (request.encoding == FrameEncoding::rgba) {
        reply.body = rgba_bytes(frame_);
        reply.content_type = "application/octet-stream";
    } else {
        reply.body = encode_png(frame_);
        reply.content_type = "image/png";
    }
    reply.encode_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    reply.command = render_command(path_, reply.camera, request.iso, request.step, step_count());
    return reply;
}

}  // namespace octiso::view
