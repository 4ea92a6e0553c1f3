// parse_frame_request: every parameter of GET /frame checked by name, form and bounds. Strict on
// purpose: the page is the only intended client, so anything it would never send is an error
// reply (never a clamp that would render something other than what was asked).
#include "view/request.h"

#include <charconv>
#include <cmath>
#include <string>
#include <system_error>

#include "octiso/error.h"

namespace octiso::view {
namespace {

/// Plain decimal: from_chars (general format) takes no '+', no spaces and no hex; it does read
/// "inf" and "nan", which the finiteness check refuses.
double to_double(const std::string& name, const std::string& text) {
    double v = 0;
    const char* end = text.data() + text.size();
    const auto [ptr, ec] = std::from_chars(text.data(), end, v, std::chars_format::general);
    if (text.empty() || ec != std::errc() || ptr != end || !std::isfinite(v))
        throw Error(name, "expected a finite decimal number, found '" + text + "'");
    return v;
}

long long to_integer(const std::string& name, const std::string& text, long long lo, long long hi) {
    long long v = 0;
    const char* end = text.data() + text.size();
    const auto [ptr, ec] = std::from_chars(text.data(), end, v);
    if (text.empty() || ec != std::errc() || ptr != end)
        throw Error(name, "expected an integer, found '" + text + "'");
    if (v < lo || v > hi)
        throw Error(name, "out of range (expected " + std::to_string(lo) + ".." + std::to_string(hi) + ", found " + text + ")");
    return v;
}

uint64_t to_counter(const std::string& name, const std::string& text) {
    uint64_t v = 0;
    const char* end = text.data() + text.size();
    const auto [ptr, ec] = std::from_chars(text.data(), end, v);
    if (text.empty() || ec != std::errc() || ptr != end)
        throw Error(name, "expected a non-negative integer, found '" + text + "'");
    return v;
}

double in_range(const std::string& name, double v, double lo, double hi) {
    if (!(v >= lo && v <= hi))
        throw Error(name, "out of range (expected " + std::to_string(lo) + ".." + std::to_string(hi) + ")");
    return v;
}

}  // namespace

FrameRequest parse_frame_request(const QueryParameters& parameters, uint32_t step_count) {
    // Before anything else: without a step to draw even the default step 0 would break the
    // promise step < step_count (fuzz_view_request found a query with no step parameter for
    // such a count; the loader refuses files without steps, so this guards the contract only).
    if (step_count == 0) throw Error("step", "the file has no steps");
    if (parameters.size() > kMaxParameters)
        throw Error("query", "too many parameters (at most " + std::to_string(kMaxParameters) + ")");
    // Each known name once; the bit says it was seen, so a repeat is caught (a proxy or a hand-
    // made URL could send "iso=1&iso=2", and which one wins would be a guess).
    enum : unsigned {
        kIso = 1, kAz = 2, kEl = 4, kZoom = 8, kW = 16, kH = 32, kStep = 64, kSeq = 128, kEnc = 256, kShadows = 512, kAo = 1024
    };
    unsigned seen = 0;
    FrameRequest r;
    for (const auto& [name, value] : parameters) {
        unsigned bit = 0;
        if (name == "iso") bit = kIso;
        else if (name == "az") bit = kAz;
        else if (name == "el") bit = kEl;
        else if (name == "zoom") bit = kZoom;
        else if (name == "w") bit = kW;
        else if (name == "h") bit = kH;
        else if (name == "step") bit = kStep;
        else if (name == "seq") bit = kSeq;
        else if (name == "enc") bit = kEnc;
        else if (name == "shadows") bit = kShadows;
        else if (name == "ao") bit = kAo;
        else throw Error(name.size() <= kMaxValueLength ? name : name.substr(0, kMaxValueLength) + "...", "unknown parameter");
        if (seen & bit) throw Error(name, "given more than once");
        seen |= bit;
        if (value.size() > kMaxValueLength)
            throw Error(name, "value longer than " + std::to_string(kMaxValueLength) + " characters");
        switch (bit) {
            case kIso: r.iso = to_double(name, value); break;
            case kAz: r.azimuth_deg = to_double(name, value); break;
            case kEl: r.elevation_deg = in_range(name, to_double(name, value), -kMaxElevationDeg, kMaxElevationDeg); break;
            case kZoom: r.zoom = in_range(name, to_double(name, value), kMinZoom, kMaxZoom); break;
            case kW: r.width = int(to_integer(name, value, 1, kMaxImageSide)); break;
            case kH: r.height = int(to_integer(name, value, 1, kMaxImageSide)); break;
            case kStep:
                r.step = uint32_t(to_integer(name, value, 0, (long long)step_count - 1));
                break;
            case kEnc:
                if (value == "png") r.encoding = FrameEncoding::png;
                else if (value == "rgba") r.encoding = FrameEncoding::rgba;
                else throw Error(name, "expected png or rgba, found '" + value + "'");
                break;
            case kShadows:   // exactly what the page sends: no "true", "on" or "01" to guess at
                if (value == "0") r.shadows = false;
                else if (value == "1") r.shadows = true;
                else throw Error(name, "expected 0 or 1, found '" + value + "'");
                break;
            case kAo: r.ao_samples = int(to_integer(name, value, 0, kMaxViewAoSamples)); break;
            default: r.seq = to_counter(name, value); break;
        }
    }
    for (const auto& [bit, name] : {std::pair{kIso, "iso"}, {kAz, "az"}, {kEl, "el"}, {kW, "w"}, {kH, "h"}})
        if (!(seen & bit)) throw Error(name, "is required");
    if ((long long)r.width * r.height > kMaxImagePixels)
        throw Error("w", "image of " + std::to_string(r.width) + "x" + std::to_string(r.height) + " exceeds " +
                             std::to_string(kMaxImagePixels) + " pixels");
    return r;
}

}  // namespace octiso::view
