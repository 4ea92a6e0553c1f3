// octiso-render's camera flags turned into the cameras of a run (issue 17, item 8): the default
// three-quarter framing, --view NAME, --azimuth/--elevation/--zoom around the data centre,
// --orbit N (N cameras around the centre), then --eye/--look/--up/--fov as explicit overrides;
// and the text that reproduces a camera (flags a user can paste back).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "cli/common/cli.h"
#include "cli/common/flags.h"
#include "octiso/camera.h"
#include "octiso/oct_file.h"

namespace octiso::cli {

struct CameraFlags {
    std::optional<std::string> eye, look, up, fov, size, view, azimuth, elevation, zoom, orbit;
    /// Adds the camera flags to `spec` (all value flags).
    static void declare(FlagSpec& spec);
    /// The camera flags as given (unparsed: cameras_for() parses them against the file).
    static CameraFlags take(const Flags& args);
};

/// The cameras of the run: one, or --orbit N of them (azimuth start + 360 i / N). Throws
/// Error(flag, ...) for a bad value or a combination that has no single meaning (--view with
/// --azimuth, --orbit with --eye ...).
std::vector<Camera> cameras_for(const CameraFlags& flags, const OctInfo& info);

/// "--eye X,Y,Z --look X,Y,Z --up X,Y,Z --fov F --size WxH", every number round-tripping.
std::string camera_flags_text(const Camera& camera);

}  // namespace octiso::cli
