// liboctiso_images.so: the image codec (image_codec.h) over OpenImageIO. The only file that
// includes OpenImageIO; it links nothing of octiso, so loading it brings in OpenImageIO alone.
// OIIO converts our buffers to whatever the file format stores (uint8 for PNG, half/float for
// EXR) when we hand it the buffer's own type.
#include <memory>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "io/image_codec.h"

namespace octiso::image_codec {
namespace {

OIIO::TypeDesc type_of(Pixel p) { return p == Pixel::f32 ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8; }

Failure other(std::string message) { return Failure{std::move(message), true}; }

std::string output_format(const std::string& path) {
    auto file = OIIO::ImageOutput::create(path);
    return file ? file->format_name() : std::string();
}

OIIO::ImageSpec spec_of(const EncodeRequest& r) {
    OIIO::ImageSpec spec(r.width, r.height, r.channels, type_of(r.file_pixel));
    spec.channelnames = *r.names;
    if (r.channels == 1) spec.alpha_channel = -1, spec.z_channel = 0;
    if (r.png_compression >= 0) spec.attribute("png:compressionLevel", r.png_compression);
    return spec;
}

Failure encode(const EncodeRequest& r, std::vector<unsigned char>& bytes, bool& in_memory) {
    auto file = OIIO::ImageOutput::create(*r.path);
    if (!file) return Failure{"no image format for this extension (" + OIIO::geterror() + ")"};
    if (!file->supports("ioproxy")) return {};
    OIIO::Filesystem::IOVecOutput memory(bytes);
    if (!file->set_ioproxy(&memory) || !file->open(*r.path, spec_of(r))) return other("cannot encode: " + file->geterror());
    if (!file->write_image(type_of(r.pixel), r.pixels)) return other("encoding failed: " + file->geterror());
    if (!file->close()) return other("encoding failed: " + file->geterror());
    in_memory = true;
    return {};
}

Failure write_file(const EncodeRequest& r, const std::string& target) {
    auto file = OIIO::ImageOutput::create(*r.path);
    if (!file) return Failure{"no image format for this extension (" + OIIO::geterror() + ")"};
    if (!file->open(target, spec_of(r))) return other("cannot open for writing: " + file->geterror());
    if (!file->write_image(type_of(r.pixel), r.pixels)) return other("write failed: " + file->geterror());
    if (!file->close()) return other("close failed: " + file->geterror());
    return {};
}

Failure read(const std::string& path, int& width, int& height, int& channels, std::vector<std::string>& names,
             std::vector<float>& pixels) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) return Failure{"cannot read image (" + OIIO::geterror() + ")"};
    const OIIO::ImageSpec& spec = in->spec();
    width = spec.width, height = spec.height, channels = spec.nchannels;
    names = spec.channelnames;
    pixels.resize(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()))
        return Failure{"cannot read pixels: " + in->geterror()};
    in->close();
    return {};
}

// OpenImageIO reports through return values; the only exception left is std::bad_alloc, which
// crosses into the caller like any other (same standard library on both sides).
constexpr ImageCodec kCodec{kImageCodecAbi, output_format, encode, write_file, read};

}  // namespace
}  // namespace octiso::image_codec

extern "C" __attribute__((visibility("default"))) const octiso::image_codec::ImageCodec* octiso_image_codec() {
    return &octiso::image_codec::kCodec;
}
