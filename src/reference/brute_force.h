// The ground-truth isosurface tracer over a dense array (no octree): every cell the ray passes
// through, in order, by an Amanatides-Woo DDA in index space, each solved by a root finder
// (Exact by default). Tests and benchmarks compare the octree renderer against it; it is never
// on the fast path. Clipping and the index-space ray are render/ray.h, the cell math roots.h.
#pragma once

#include <array>
#include <cstdint>
#include <limits>

#include "octiso/volume.h"
#include "math/ray.h"
#include "render/roots.h"

namespace octiso {

/// One reference hit. t: world distance along the unit ray (+inf on a miss); normal: world unit
/// normal facing the ray (0,0,0 on a miss); cell: lower corner index of the hit cell.
struct RefHit {
    double t = std::numeric_limits<double>::infinity();
    std::array<double, 3> normal{0.0, 0.0, 0.0};
    uint32_t cell[3] = {0, 0, 0};
    bool is_hit() const { return t < std::numeric_limits<double>::infinity(); }
};

/// First isosurface hit with t in [ray_world.t_min, ray_world.t_max] (default [0, +inf]) of `ray_world` (unit direction) in the volume placed by
/// `placement`, under the hit policies of CONVENTIONS 2b: each cell owns [t_in, t_out) of the ray,
/// the last cell before the ray leaves the data its closed piece; cells with a non-finite corner
/// are skipped. A volume with an extent < 2 has no cells and is never hit. Thread-safe.
/// Instantiated for the 8 scalar types and the 4 root finders in brute_force.cpp.
template <typename T, typename Finder = Exact>
RefHit trace_reference(const VolumeView<T>& volume, const Placement& placement, const Ray& ray_world, double iso,
                       const Finder& finder = Finder{});

}  // namespace octiso
