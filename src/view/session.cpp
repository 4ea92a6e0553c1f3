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
#include "octiso/look.h"
#include "octiso/oct_file.h"
#include "octiso/render.h"
#include "octiso/shading.h"
#include "octiso/value_stats.h"
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

/// /info in real values: the ranges mapped by the file's value_scale (ends swapped by a negative
/// slope), the scale itself given so the page can say what the numbers are.
std::string build_info_json(const std::string& path, const OctInfo& info, const AnyOctreeInfo& step0, const Histogram& h,
                            std::optional<double> initial_iso) {
    std::string j = "{\"file\":" + json_string(path) + ",\"type\":" + json_string(std::string(scalar_type_name(info.type)));
    j += ",\"dims\":[" + std::to_string(info.dims.x) + "," + std::to_string(info.dims.y) + "," + std::to_string(info.dims.z) + "]";
    j += ",\"spacing\":[" + vec3(info.placement.spacing) + "],\"origin\":[" + vec3(info.placement.origin) + "]";
    j += ",\"steps\":" + std::to_string(info.step_count);
    auto range = [&](const std::optional<std::array<double, 2>>& stored) {
        if (!stored) return std::string("null");
        const std::array<double, 2> r = info.value_scale.real_range(*stored);
        return "[" + json_number(r[0]) + "," + json_number(r[1]) + "]";
    };
    j += ",\"value_range\":" + range(step0.value_range) + ",\"iso_range\":" + range(info.iso_range);
    j += ",\"value_scale\":[" + exact(info.value_scale.slope) + "," + exact(info.value_scale.inter) + "]";
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
    const AnyOctreeInfo info = step.info();
    if (!info.value_range) return h;
    const ValueScale scale = info.value_scale;
    const std::array<double, 2> range = scale.real_range(*info.value_range);
    h.lo = range[0], h.hi = range[1];
    if (bins <= 0) return h;
    if (step.dense_bytes() > max_dense_bytes) {
        // Too large to decode (the 2048x2048x1920 step is 7.5 GiB dense): the histogram from the
        // tree (value_stats.h: a scalar leaf counts once for all its voxels, caps voxel by voxel),
        // in stored-value bins over the voxels' exact range, turned into real values. The
        // scale is affine, so bins of equal stored width are bins of equal real width; a
        // negative slope reverses their order. value_stats reads the step three times: past
        // kTreeHistogramFileBytes (a file the page cache may not hold: the 21 GiB step of the
        // larger-than-RAM run would take minutes) the page goes without one.
        constexpr uint64_t kTreeHistogramFileBytes = uint64_t(4) << 30;
        if (step.file() && step.file()->file_bytes() > kTreeHistogramFileBytes) return h;
        const ValueStats stats = value_stats(step, bins);
        const std::array<double, 2> real = scale.real_range(stats.range);
        h.lo = real[0], h.hi = real[1];
        h.counts = stats.counts;
        if (scale.slope < 0) std::reverse(h.counts.begin(), h.counts.end());
        return h;
    }
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
            const double x = scale.real(double(v));   // the same map as the range's ends
            // value_range covers data cells only (an extent-1 border voxel can lie outside it).
            if (!(x >= h.lo && x <= h.hi)) continue;
            const double f = width > 0 ? (x - h.lo) / width * bins : 0.0;
            h.counts[std::min(size_t(bins) - 1, size_t(f))]++;
        }
    });
    return h;
}

std::string render_command(const std::string& path, const Camera& camera, double iso, const Look& look, double lod, uint32_t step,
                           uint32_t step_count) {
    std::string c = "octiso-render " + shell_quote(path) + " --iso " + exact(iso);
    if (lod > 0) c += " --lod " + exact(lod);
    // Without the look the viewer shows the Renderer's own colour (headlight); octiso-render's
    // default is the light kit (deferred shading), so the command names the headlight to
    // reproduce the frame exactly. Shadows and AO need the kit, octiso-render's default.
    if (!look.active()) c += " --shading headlight";
    if (look.shadows) c += " --shadows";
    if (look.ao_samples > 0) c += " --ao " + std::to_string(look.ao_samples);
    c += " --eye " + vec3(camera.eye) + " --look " + vec3(camera.look) + " --up " + vec3(camera.up);
    c += " --fov " + exact(camera.fov_deg) + " --size " + std::to_string(camera.width) + "x" + std::to_string(camera.height);
    // octiso-render renders step k of a series with --steps k:k and a name pattern.
    if (step_count > 1) c += " --steps " + std::to_string(step) + ":" + std::to_string(step) + " -o frame_%04d.png";
    else c += " -o frame.png";
    return c;
}

namespace {
/// The level-of-detail factor, checked before the file is opened (a bad flag is named first).
double checked_lod(double lod) {
    if (!(std::isfinite(lod) && lod >= 0)) throw Error("--lod", "expected a finite factor >= 0 (0: full resolution)");
    return lod;
}
}  // namespace

ViewSession::ViewSession(const std::string& path, int threads, std::optional<double> initial_iso, double lod)
    : path_(path), threads_(threads), lod_(checked_lod(lod)), file_(std::make_shared<const OctFile>(OctFile::open(path))) {
    if (file_->info().step_count == 0) throw Error(path, "the file has no steps");
    scale_ = file_->info().value_scale;
    renderers_.resize(file_->info().step_count);
    const AnyOctree step0 = AnyOctree::step(file_, 0);   // validated now: a bad file fails before serving
    histogram_ = value_histogram(step0, 128, uint64_t(1) << 30);
    if (initial_iso) check_iso_range(*initial_iso, "--iso");   // refused now, not as a first frame the page cannot show
    info_json_ = build_info_json(path_, file_->info(), step0.info(), histogram_, initial_iso);
}

void ViewSession::check_iso_range(double real_iso, const std::string& subject) const {
    // The Renderer checks the stored value against the stored iso-range too (validate_options),
    // but names both in stored values; this is the same test, worded in the values the user sees.
    const auto& stored_range = file_->info().iso_range;
    if (!stored_range) return;
    const double stored = scale_.stored(real_iso);
    if (stored > (*stored_range)[0] && stored < (*stored_range)[1]) return;
    const std::array<double, 2> r = scale_.real_range(*stored_range);
    throw Error(subject, "isovalue " + exact(real_iso) + " lies outside the file's iso-range (" + exact(r[0]) + ", " + exact(r[1]) +
                             "): the data there was clamped when " + path_ + " was converted");
}

Camera ViewSession::camera_for(const FrameRequest& r) const {
    const OctInfo& info = file_->info();
    return orbit_camera(info.dims, info.placement, r.width, r.height, r.azimuth_deg, r.elevation_deg, r.zoom);
}

FrameReply ViewSession::render(const FrameRequest& request) {
    if (request.step >= renderers_.size()) throw Error("step", "out of range");
    check_iso_range(request.iso, "iso");
    RenderOptions options;
    // CONVENTIONS 2b: the page's isovalue is real; the tree holds stored values. The same
    // conversion as octiso-render's (ValueScale::stored of the same double), so the offered
    // command, which carries the real value, traces the same stored isovalue bit for bit.
    options.isovalues = {scale_.stored(request.iso)};
    options.threads = threads_;
    options.lod = lod_;
    // The kernel directly, without Embree's dispatch: the same pixels (RenderPaths.
    // EmbreeAndDirectGiveIdenticalFrames, colour and AOVs), 1-5 % less per frame (BENCHMARKS.md, packets).
    options.use_embree = false;
    Look look;
    look.shadows = request.shadows;
    look.ao_samples = request.ao_samples;
    // octiso-render's deferred path for a look (render_main.cpp): the tile loop writes only the
    // AOVs, and the LookShader colours the frame from them with the light kit.
    if (look.active()) options.want_colour = false, options.want_depth = options.want_normal = true;
    std::unique_ptr<Renderer>& renderer = renderers_[request.step];
    const auto make_tree = [&] { return AnyOctree::step(file_, request.step); };
    if (!renderer) renderer = std::make_unique<Renderer>(make_tree().make_renderer(options));
    else renderer->set_options(options);   // validates the isovalue against the file's iso-range
    if (look.active() && !(look_.shader && look_.step == request.step && look_.stored_iso == options.isovalues[0] &&
                           look_.shadows == look.shadows && look_.ao_samples == look.ao_samples)) {
        look_.shader.reset();
        look_.shader.emplace(make_tree(), options, look, ShadingModel::kit);
        look_.step = request.step, look_.stored_iso = options.isovalues[0];
        look_.shadows = look.shadows, look_.ao_samples = look.ao_samples;
    }
    FrameReply reply;
    reply.camera = camera_for(request);
    reply.stats = renderer->render(reply.camera, frame_);
    if (look.active()) reply.look = look_.shader->shade(reply.camera, Shading{}, frame_);
    const auto t0 = std::chrono::steady_clock::now();
    if (request.encoding == FrameEncoding::rgba) {
        reply.body = rgba_bytes(frame_);
        reply.content_type = "application/octet-stream";
    } else {
        reply.body = encode_png(frame_, threads_);
        reply.content_type = "image/png";
    }
    reply.encode_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    reply.command = render_command(path_, reply.camera, request.iso, look, lod_, request.step, step_count());
    return reply;
}

}  // namespace octiso::view
