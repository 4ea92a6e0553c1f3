// Image files through OpenImageIO (CONVENTIONS 2): the format follows the extension; colour is
// 8-bit sRGB unless the format is floating point; the depth AOV is one float channel named Z; the
// normal AOV three float channels R,G,B. Every write goes to a temporary name renamed on success.
// The colour image of a .png name (any case) is written by libpng and the depth and normal images
// of an .exr name by OpenEXR, without OpenImageIO; everything else loads OpenImageIO on its first
// call (the module liboctiso_images.so, beside the tools in the build tree, in lib/octiso when
// installed; $OCTISO_IMAGE_MODULE names another); if it cannot be, the call throws
// Error(ErrorKind::Other) naming the module.
#pragma once

#include <string>
#include <vector>

#include "octiso/frame.h"

namespace octiso {

/// Writes frame.rgb. Throws Error(path, ...) if the format is unknown or the write fails.
/// `threads` encode a PNG's strips of rows (1: the calling thread; 0: every core; the same bytes
/// on any count); other formats ignore it.
void write_colour_image(const std::string& path, const Frame& frame, int threads = 1);
/// Writes frame.depth as channel "Z" (+inf on a miss where the format allows, else a large value).
/// `threads` compress an OpenEXR file's blocks (1: the calling thread; 0: every hardware thread;
/// the same bytes on any count); other formats ignore it.
void write_depth_image(const std::string& path, const Frame& frame, int threads = 1);
/// Writes frame.normal as float R,G,B (`threads` as write_depth_image).
void write_normal_image(const std::string& path, const Frame& frame, int threads = 1);

/// What an image file will hold: the 8-bit colour (write_colour_image) or an AOV (depth, normal:
/// floats, or mapped to 8 bits by OpenImageIO where the format holds no floats).
enum class ImageContent { Colour, Aov };
/// Checks before rendering that `path` names a format we can write `content` to (a colour .png or
/// an AOV .exr, which need no module, or an extension OpenImageIO knows, which loads it), so a long render
/// never ends in an unwritable file or without its module. Throws Error(flag, ...).
void check_image_path(const std::string& path, const std::string& flag, ImageContent content);
/// Whether the format of `path` (by extension) stores float channels (EXR, TIFF, HDR, FITS, PFM):
/// the formats a depth image keeps its distances in. Throws Error(path, ...) for an unknown format.
bool image_format_holds_floats(const std::string& path);

/// A float image read back (tests, comparisons): width x height x channels, row 0 at the top.
struct FloatImage {
    int width = 0, height = 0, channels = 0;
    std::vector<std::string> channel_names;
    std::vector<float> pixels;
};
FloatImage read_image(const std::string& path);

}  // namespace octiso
