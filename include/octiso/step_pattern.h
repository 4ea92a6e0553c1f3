// Names of the steps of a time series: a printf pattern with exactly one integer field
// (t_%03d.raw, frame_%04d.png), expanded for step k. The converter's --steps sources and the
// renderer's per-step output names both go through it, so both accept the same patterns.
#pragma once

#include <string>

namespace octiso {

/// Expands the one printf integer field of `pattern` (%d, %4d, %04d; "%%" is a literal percent)
/// with k. Throws Error(flag, ...) unless the pattern holds exactly one %d-style field.
std::string format_step(const std::string& pattern, long long k, const std::string& flag);

}  // namespace octiso
