// OpenImageIO behind include/octiso/image.h. OIIO converts our buffers to whatever the file
// format stores (uint8 for PNG, half/float for EXR) when we hand it the buffer's own type.
#include <algorithm>
#include <cmath>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "util/atomic_output.h"
#include "octiso/error.h"
#include "octiso/image.h"

namespace octiso {

namespace {

void write_image(const std::string& path, int width, int height, int channels, OIIO::TypeDesc type, const void* pixels,
                 const std::vector<std::string>& names, OIIO::TypeDesc file_type) {
    auto file = OIIO::ImageOutput::create(path);
    if (!file) throw Error(path, "no image format for this extension (" + OIIO::geterror() + ")");
    OIIO::ImageSpec spec(width, height, channels, file_type);
    spec.channelnames = names;
    if (channels == 1) spec.alpha_channel = -1, spec.z_channel = 0;
    // Encode into memory, then write the bytes ourselves with every write checked: OIIO's PNG
    // writer did not report ENOSPC, and a truncated PNG was renamed into place (issue 18).
    if (file->supports("ioproxy")) {
        std::vector<unsigned char> bytes;
        OIIO::Filesystem::IOVecOutput memory(bytes);
        if (!file->set_ioproxy(&memory) || !file->open(path, spec))
            throw Error(path, "cannot encode: " + file->geterror(), ErrorKind::Other);
        if (!file->write_image(type, pixels)) throw Error(path, "encoding failed: " + file->geterror(), ErrorKind::Other);
        if (!file->close()) throw Error(path, "encoding failed: " + file->geterror(), ErrorKind::Other);
        write_file_atomically(path, bytes.data(), bytes.size());
        return;
    }
    // A format without I/O proxies writes its own file; commit() still fsyncs it (which reports
    // deferred write errors) before the rename.
    AtomicOutput out(path);
    if (!file->open(out.temp_path(), spec)) throw Error(path, "cannot open for writing: " + file->geterror(), ErrorKind::Other);
    if (!file->write_image(type, pixels)) throw Error(path, "write failed: " + file->geterror(), ErrorKind::Other);
    if (!file->close()) throw Error(path, "close failed: " + file->geterror(), ErrorKind::Other);
    out.commit();
}

/// The float type a file format can hold: float where supported, else its native 8 bits.
OIIO::TypeDesc float_or_native(const std::string& path) {
    auto probe = OIIO::ImageOutput::create(path);
    if (!probe) throw Error(path, "no image format for this extension");
    const std::string fmt = probe->format_name();
    if (fmt == "openexr" || fmt == "tiff" || fmt == "hdr" || fmt == "fits" || fmt == "pfm") return OIIO::TypeDesc::FLOAT;
    return OIIO::TypeDesc::UINT8;
}

}  // namespace

void check_image_path(const std::string& path, const std::string& flag) {
    if (!OIIO::ImageOutput::create(path)) throw Error(flag, "'" + path + "': no image format for this extension");
}

bool image_format_holds_floats(const std::string& path) { return float_or_native(path) == OIIO::TypeDesc::FLOAT; }

void write_colour_image(const std::string& path, const Frame& frame) {
    if (frame.rgb.empty()) throw Error(path, "the frame has no colour image", ErrorKind::Other);
    write_image(path, frame.width, frame.height, 3, OIIO::TypeDesc::UINT8, frame.rgb.data(), {"R", "G", "B"},
                OIIO::TypeDesc::UINT8);
}

void write_depth_image(const std::string& path, const Frame& frame) {
    if (frame.depth.empty()) throw Error(path, "the frame has no depth image", ErrorKind::Other);
    const OIIO::TypeDesc type = float_or_native(path);
    if (type == OIIO::TypeDesc::FLOAT) {
        write_image(path, frame.width, frame.height, 1, OIIO::TypeDesc::FLOAT, frame.depth.data(), {"Z"}, type);
        return;
    }
    // An 8-bit format cannot hold distances: scale the hit range to [1/255, 1], misses 0.
    float lo = INFINITY, hi = -INFINITY;
    for (float t : frame.depth)
        if (std::isfinite(t)) lo = std::min(lo, t), hi = std::max(hi, t);
    std::vector<float> scaled(frame.depth.size(), 0.0f);
    for (size_t i = 0; i < scaled.size(); ++i)
        if (std::isfinite(frame.depth[i])) scaled[i] = hi > lo ? 1.0f - 0.996f * (frame.depth[i] - lo) / (hi - lo) : 1.0f;
    write_image(path, frame.width, frame.height, 1, OIIO::TypeDesc::FLOAT, scaled.data(), {"Z"}, type);
}

void write_normal_image(const std::string& path, const Frame& frame) {
    if (frame.normal.empty()) throw Error(path, "the frame has no normal image", ErrorKind::Other);
    const OIIO::TypeDesc type = float_or_native(path);
    if (type == OIIO::TypeDesc::FLOAT) {
        write_image(path, frame.width, frame.height, 3, OIIO::TypeDesc::FLOAT, frame.normal.data(), {"R", "G", "B"}, type);
        return;
    }
    std::vector<float> mapped(frame.normal.size());   // 8-bit: the usual n * 0.5 + 0.5 encoding
    for (size_t i = 0; i < mapped.size(); ++i) mapped[i] = frame.normal[i] * 0.5f + 0.5f;
    write_image(path, frame.width, frame.height, 3, OIIO::TypeDesc::FLOAT, mapped.data(), {"R", "G", "B"}, type);
}

FloatImage read_image(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw Error(path, "cannot read image (" + OIIO::geterror() + ")");
    const OIIO::ImageSpec& spec = in->spec();
    FloatImage img;
    img.width = spec.width, img.height = spec.height, img.channels = spec.nchannels;
    img.channel_names = spec.channelnames;
    img.pixels.resize(size_t(spec.width) * spec.height * spec.nchannels);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, img.pixels.data()))
        throw Error(path, "cannot read pixels: " + in->geterror());
    in->close();
    return img;
}

}  // namespace octiso
