// Limits that several layers share and that the .oct format or the renderer's fixed per-ray
// arrays depend on. Value-only: no types, no functions.
#pragma once

namespace octiso {

/// Isovalues per frame: each has its own colour, and the per-ray isovalue arrays are this long.
inline constexpr int kMaxIsovalues = 8;

}  // namespace octiso
