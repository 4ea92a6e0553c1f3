// Depth compositing of brick frames (octiso/depth_composite.h).
#include "octiso/depth_composite.h"

#include <cstring>
#include <limits>
#include <string>

#include "octiso/error.h"

namespace octiso {
namespace {

void check_size(size_t pixels, const CompositeLayout& layout, size_t bytes, const char* what) {
    if (bytes != pixels * layout.sample_bytes())
        throw Error(what, std::to_string(bytes) + " bytes for " + std::to_string(pixels) + " samples of " +
                              std::to_string(layout.sample_bytes()) + " bytes",
                    ErrorKind::Other);
}

}  // namespace

void pack_composite(const Frame& frame, uint32_t ordinal, const CompositeLayout& layout, std::span<std::byte> out) {
    const size_t pixels = size_t(frame.width) * size_t(frame.height);
    check_size(pixels, layout, out.size(), "pack_composite");
    if (frame.depth.size() != pixels || (layout.colour && frame.rgb.size() != 3 * pixels) ||
        (layout.normal && frame.normal.size() != 3 * pixels))
        throw Error("pack_composite", "the frame lacks an output the layout carries", ErrorKind::Other);
    std::byte* p = out.data();
    for (size_t i = 0; i < pixels; ++i) {
        std::memcpy(p, &frame.depth[i], 4);
        std::memcpy(p + 4, &ordinal, 4);
        p += 8;
        if (layout.colour) {
            const uint8_t rgb[4] = {frame.rgb[3 * i], frame.rgb[3 * i + 1], frame.rgb[3 * i + 2], 0};
            std::memcpy(p, rgb, 4);
            p += 4;
        }
        if (layout.normal) {
            std::memcpy(p, &frame.normal[3 * i], 12);
            p += 12;
        }
    }
}

void composite_nearer(const std::byte* in, std::byte* inout, size_t count, const CompositeLayout& layout) {
    const size_t bytes = layout.sample_bytes();
    for (size_t i = 0; i < count; ++i, in += bytes, inout += bytes) {
        float d_in, d_out;
        uint32_t o_in, o_out;
        std::memcpy(&d_in, in, 4), std::memcpy(&o_in, in + 4, 4);
        std::memcpy(&d_out, inout, 4), std::memcpy(&o_out, inout + 4, 4);
        if (d_in < d_out || (d_in == d_out && o_in < o_out)) std::memcpy(inout, in, bytes);
    }
}

void unpack_composite(std::span<const std::byte> samples, const CompositeLayout& layout, Frame& frame) {
    const size_t pixels = size_t(frame.width) * size_t(frame.height);
    check_size(pixels, layout, samples.size(), "unpack_composite");
    const bool depth = frame.depth.size() == pixels, rgb = layout.colour && frame.rgb.size() == 3 * pixels,
               normal = layout.normal && frame.normal.size() == 3 * pixels;
    const std::byte* p = samples.data();
    uint64_t hits = 0;
    for (size_t i = 0; i < pixels; ++i) {
        float d;
        std::memcpy(&d, p, 4);
        hits += d < std::numeric_limits<float>::infinity();
        if (depth) frame.depth[i] = d;
        p += 8;
        if (layout.colour) {
            if (rgb) std::memcpy(&frame.rgb[3 * i], p, 3);
            p += 4;
        }
        if (layout.normal) {
            if (normal) std::memcpy(&frame.normal[3 * i], p, 12);
            p += 12;
        }
    }
    frame.stats.hits = hits;
}

}  // namespace octiso
