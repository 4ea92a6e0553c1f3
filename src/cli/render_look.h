// octiso-render's flags of the ray-traced look (issue 17 item 7): --shadows, --ao N,
// --ao-distance VOXELS, --opacity A (once per isovalue), --clip NX,NY,NZ,D (repeatable) and --clip-cap, read
// in one place so that the tool's main function only hands them on (octiso/look.h, RenderOptions).
#pragma once

#include <string>
#include <vector>

#include "cli/common/cli.h"
#include "cli/common/flags.h"
#include "cli/common/json.h"
#include "octiso/look.h"
#include "octiso/render.h"

namespace octiso::cli {

struct LookFlags {
    Look look;
    std::vector<ClipPlane> clip_planes;
    bool clip_cap = false;   ///< --clip-cap: the cut faces drawn where they cut an inside (octiso/clip_cap.h)
    /// Adds the look flags to `spec` (--opacity and --clip repeatable).
    static void declare(FlagSpec& spec);
    /// Reads the look flags from `args`; throws Error(flag, ...) for a malformed value.
    static LookFlags take(const Flags& args);
};

/// The help text of these flags (one block of octiso-render --help).
extern const char* const kLookUsage;

/// The run's look as "look": {...} in the run's --json object (only when a flag is given).
void write_look_json(JsonWriter& j, const LookFlags& flags);
/// One frame's look cost: "secondary": {...} in its --json object, or the text report's line.
void write_look_stats_json(JsonWriter& j, const LookStats& stats);
void print_look_stats(const LookStats& stats);

}  // namespace octiso::cli
