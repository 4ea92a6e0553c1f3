// octiso-render's flags of the ray-traced look (issue 17 item 7): --shadows, --ao N,
// --ao-distance VOXELS, --opacity A (once per isovalue) and --clip NX,NY,NZ,D (repeatable), read
// in one place so that the tool's main function only hands them on (octiso/look.h, RenderOptions).
#pragma once

#include <string>
#include <vector>

#include "cli/common/cli.h"
#include "octiso/look.h"
#include "octiso/render.h"

namespace octiso::cli {

struct LookFlags {
    Look look;
    std::vector<ClipPlane> clip_planes;
    /// Consumes the look flags from `args`; throws Error(flag, ...) for a malformed value.
    static LookFlags take(Args& args);
};

/// The help text of these flags (one block of octiso-render --help).
extern const char* const kLookUsage;

}  // namespace octiso::cli
