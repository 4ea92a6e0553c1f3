// libFuzzer target: octiso-view's /frame parameter parser (src/view/request.h), the only text of
// a request the viewer itself reads (cpp-httplib has split and percent-decoded the query). The
// input is the name/value pairs, one per line as NAME=VALUE, after a first byte that sets the
// file's step count; any bytes, NULs included, may appear in names and values.
#include <cstdint>
#include <string>

#include "octiso/error.h"
#include "view/request.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    const uint32_t step_count = data[0];
    octiso::view::QueryParameters parameters;
    const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
    size_t start = 0;
    while (start <= text.size()) {
        size_t end = text.find('\n', start);
        if (end == std::string::npos) end = text.size();
        const std::string line = text.substr(start, end - start);
        const size_t eq = line.find('=');
        parameters.emplace_back(line.substr(0, eq), eq == std::string::npos ? std::string() : line.substr(eq + 1));
        start = end + 1;
    }
    try {
        const octiso::view::FrameRequest r = octiso::view::parse_frame_request(parameters, step_count);
        // What the parser promises (request.h), checked on every accepted input.
        if (!(r.width >= 1 && r.height >= 1 && r.width <= octiso::view::kMaxImageSide &&
              r.height <= octiso::view::kMaxImageSide &&
              (long long)r.width * r.height <= octiso::view::kMaxImagePixels && r.step < step_count &&
              r.zoom >= octiso::view::kMinZoom && r.zoom <= octiso::view::kMaxZoom &&
              r.elevation_deg >= -octiso::view::kMaxElevationDeg && r.elevation_deg <= octiso::view::kMaxElevationDeg &&
              r.iso - r.iso == 0 && r.azimuth_deg - r.azimuth_deg == 0 &&
              (r.encoding == octiso::view::FrameEncoding::png || r.encoding == octiso::view::FrameEncoding::rgba)))
            __builtin_trap();
    } catch (const octiso::Error&) {
    }
    return 0;
}
