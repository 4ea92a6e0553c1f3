// Synthetic volumes for tests, benchmarks and demos: deterministic generators (own hash, no
// std::random distributions) filled in parallel with TBB into an owning buffer. Names follow
// `--synthetic NAME:N` or `NAME:NX,NY,NZ`; plume-series adds a step count (NAME:N,STEPS).
//
//   sphere          distance in voxels from the grid centre (f32; integer types round it)
//   marschner-lobb  Marschner & Lobb 1994 test signal, alpha 0.25, fM 6, on [-1,1]^3 (f32, [0,1])
//   sponge          Menger (Sierpinski) sponge, solid 255 / hole 0 (u8); alias "sierpinski"
//   noise           multi-octave hash value noise plus per-voxel hash, [0,255]: nothing merges (u8)
//   plume           rising combustion-like plume in a uniform ambient (0), z is up (u8)
//   mixing          Richtmyer-Meshkov-like mixing layer: 255 below, 0 above, a perturbed,
//                   multi-scale mixing band between them (u8)
//   plume-series    the plume at time step k (k = 0 is `plume`)
//   ct-head         CT-like head in Hounsfield units: air, soft tissue, porous skull, brain,
//                   ventricles, 12 HU of scanner noise everywhere (i16)
//
// Values sit on the generator's natural scale; an integer T gets them multiplied by the
// generator's integer scale (255 for marschner-lobb, else 1), rounded and clamped to T's range.
// plume and mixing are integer-valued on every type (quantized like real u8 simulation output).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "octiso/loaded_volume.h"
#include "octiso/volume.h"

namespace octiso {

struct SyntheticSpec {
    std::string name;     ///< canonical name (alias resolved), e.g. "plume-series"
    Dims dims;
    uint32_t steps = 1;   ///< > 1 only for plume-series
};

/// Parses NAME:N, NAME:NX,NY,NZ (and for plume-series NAME:N,STEPS or NAME:NX,NY,NZ,STEPS).
/// Throws Error(flag, ...) for an unknown name or malformed sizes.
SyntheticSpec parse_synthetic(std::string_view text, const std::string& flag = "--synthetic");

/// The canonical generator names, for usage messages.
std::vector<std::string> synthetic_names();

/// The type a generator produces when --type does not override it.
ScalarType synthetic_default_type(std::string_view name);

/// Voxels of generator `name` at time step k (only plume-series/plume vary with k), x fastest.
/// Deterministic across runs, thread counts and platforms with IEEE doubles.
template <typename T> std::vector<T> generate_synthetic(std::string_view name, Dims dims, uint32_t k = 0);

/// Step k of `name` as an owning LoadedVolume (format synthetic, spacing 1, origin 0); the source
/// string is "name:NX,NY,NZ" (plus "@k" for k > 0). type defaults to synthetic_default_type().
LoadedVolume synthetic_step(std::string_view name, Dims dims, uint32_t k, std::optional<ScalarType> type = {});

/// synthetic_step(spec.name, spec.dims, 0, type).
LoadedVolume make_synthetic(const SyntheticSpec& spec, std::optional<ScalarType> type = {});

}  // namespace octiso
