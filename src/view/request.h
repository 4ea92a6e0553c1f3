// The viewer's request parameters: the query of GET /frame (isovalue, orbit angles, zoom, image
// size, series step, client sequence number) parsed and bounded before anything is rendered. The
// only untrusted text the viewer reads (the HTTP framing itself is cpp-httplib's); fuzz/
// fuzz_view_request.cpp feeds it arbitrary bytes. Rendering and replies are session.h and server.h.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace octiso::view {

/// Bounds on what a request may ask for, so no client can make the server allocate or render
/// without limit (issue 20, "safe as a server").
inline constexpr int kMaxImageSide = 4096;                  ///< pixels, width and height each
inline constexpr long long kMaxImagePixels = 2048LL * 2048;  ///< width x height (12 MiB of RGB)
inline constexpr size_t kMaxParameters = 16;                ///< name=value pairs in one query
inline constexpr size_t kMaxValueLength = 64;               ///< characters of one value
inline constexpr double kMaxElevationDeg = 89.0;            ///< |elevation| < 90 keeps z-up defined
inline constexpr double kMinZoom = 0.05, kMaxZoom = 50.0;

/// How a frame's pixels travel. png: lossless and compact (OpenImageIO, zlib level 1; 105 KB for
/// ch2better at 512^2), for a page on another machine; rgba: the tile loop's colour as raw 8-bit
/// RGBA rows (alpha 255, 1 MB at 512^2), which the page wraps as ImageData without decoding. On
/// loopback rgba is the faster one: at 512^2 the PNG encode took 16-25 ms p50 and Chromium's
/// decode 5-7 ms, the raw body arrives and is wrapped in about 4 ms (bench/interactive_browser.py
/// --encodings rgba,png, BENCHMARKS.md viewer section).
enum class FrameEncoding { png, rgba };

/// One frame asked for: the camera of orbit_camera(dims, placement, width, height, azimuth_deg,
/// elevation_deg, zoom) and the isovalue `iso` of series step `step`.
/// Invariants after parse_frame_request: iso, azimuth_deg finite; |elevation_deg| <= kMaxElevationDeg;
/// zoom in [kMinZoom, kMaxZoom]; 1 <= width, height <= kMaxImageSide, width*height <= kMaxImagePixels;
/// step < the file's step count.
struct FrameRequest {
    double iso = 0;
    double azimuth_deg = 0, elevation_deg = 0, zoom = 1;
    int width = 512, height = 512;
    uint32_t step = 0;
    uint64_t seq = 0;   ///< the client's counter, echoed back so it can drop replies older than shown
    FrameEncoding encoding = FrameEncoding::png;
};

using QueryParameters = std::vector<std::pair<std::string, std::string>>;

/// Parses the (already percent-decoded) name/value pairs of a /frame query for a file of
/// `step_count` steps. iso, az, el, w, h are required; zoom (1), step (0), seq (0) and
/// enc (png; or rgba) optional.
/// Throws Error(parameter name, problem) for a missing, repeated, unknown, malformed or out-of-
/// bounds parameter. Numbers are plain decimal (no sign '+', no spaces, no inf/nan, no hex).
FrameRequest parse_frame_request(const QueryParameters& parameters, uint32_t step_count);

}  // namespace octiso::view
