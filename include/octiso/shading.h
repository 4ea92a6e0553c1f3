// Deferred shading of a rendered frame (octiso-render's colour, issue 17 item 6): the colour is
// computed after tracing, from the frame's depth and normal AOVs, so that the light model, the
// background and the colour of each isovalue are choices of the caller and the tracer stays as it
// is. Which isovalue a pixel shows is read back from the field at its hit point (the isovalue
// nearest to the value there). The Renderer's own headlight shading (src/render/shade.h) is the
// other path; ShadingModel::headlight here reproduces its formula, for custom colours.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "octiso/any_octree.h"
#include "octiso/camera.h"
#include "octiso/clip_cap.h"
#include "octiso/frame.h"

namespace octiso {

enum class ShadingModel {
    kit,         ///< key + fill + head + two back lights fixed to the camera, a little specular (src/render/light_kit.h)
    headlight,   ///< Lambert from the eye plus ambient: the Renderer's own shading
};

/// Colours are linear RGB in [0, 1].
struct Shading {
    ShadingModel model = ShadingModel::kit;
    std::array<float, 3> background{0.015f, 0.017f, 0.022f};   ///< the Renderer's background
    /// colours[i], where given, replaces the albedo of isovalue i (default: the Renderer's palette).
    std::vector<std::optional<std::array<float, 3>>> colours;
    /// --clip-cap: the caps cap_clip_planes drew into the frame; a hit on one shows the innermost
    /// isovalue whose inside holds it, not the isovalue nearest to the field there.
    std::optional<ClipCap> cap;
    /// Threads of the pass (rows in parallel; 0: all cores), as RenderOptions::threads. The pixels
    /// are independent, so the frame is the same bit for bit on any count.
    int threads = 0;
};

/// Fills frame.rgb (8-bit sRGB, resized to the frame) from frame.depth and frame.normal, both
/// required, as rendered by `tree` with `isovalues` through `camera` (its pixel_offset included).
/// Throws Error(..., Other) when an AOV is missing. Thread-safe for distinct frames.
void shade_frame(const AnyOctree& tree, const std::vector<double>& isovalues, const Camera& camera, const Shading& shading,
                 Frame& frame);

/// Parses a colour as the tools take it: "R,G,B" with each in [0, 1] or "#RRGGBB", both as shown
/// on screen (sRGB), into linear RGB. Throws Error(flag, ...).
std::array<float, 3> parse_colour(const std::string& text, const std::string& flag);

}  // namespace octiso
