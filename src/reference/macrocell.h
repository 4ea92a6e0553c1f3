// The hierarchical macrocell grid of Parker et al. 1998 (the baseline of Knoll et al. 2006, Table 3):
// levels of B^3 macrocells holding the [min, max] of their cells (forward layer included), walked by
// a nested DDA down to the cells, which are solved with the octree tracer's root finders, hit
// policies and ray clip, so the images agree. Corners come from a policy: the dense array, or an
// Octree<T> (point location, then neighbour finding), giving the paper's 2x2 table.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "octiso/octree.h"
#include "octiso/limits.h"
#include "octiso/volume.h"
#include "math/ray.h"
#include "render/cell_dda.h"
#include "render/roots.h"
#include "render/traverse.h"

namespace octiso {

struct MacrocellOptions {
    int branching = 4;   ///< B: a macrocell of level l+1 holds B^3 of level l (level 0: the cells)
    int levels = 3;      ///< macrocell levels above the cells; 0 is a plain DDA over every cell
};

/// MacrocellGrid<T>: per level l = 1 .. levels, count(l)[a] = ceil(n_cells[a] / B^l) macrocells per
/// axis; macrocell m covers cells [m B^l, min((m+1) B^l, n_cells)) per axis, and its [min, max]
/// bounds every corner of those cells (so the forward voxel layer counts). Non-finite values are
/// left out of the ranges (such cells are skipped by the hit policies anyway); a macrocell with
/// no finite value has min > max and is never entered. Owns its ranges; the volume is not kept.
template <typename T> class MacrocellGrid {
public:
    /// Throws Error("--branching"/"--levels", ...) for B < 2 or levels outside [0, 10].
    MacrocellGrid(const VolumeView<T>& volume, const MacrocellOptions& options);

    Dims dims() const { return dims_; }
    int levels() const { return levels_; }
    int branching() const { return branching_; }
    /// Macrocells per axis at level l (level 0: the cells).
    const std::array<int64_t, 3>& count(int l) const { return count_[size_t(l)]; }
    /// Range of macrocell (i, j, k) of level l >= 1.
    T min_at(int l, int64_t i, int64_t j, int64_t k) const { return min_[size_t(l)][flat(l, i, j, k)]; }
    T max_at(int l, int64_t i, int64_t j, int64_t k) const { return max_[size_t(l)][flat(l, i, j, k)]; }
    /// Bytes of the min/max arrays (the acceleration structure alone, not the data).
    uint64_t bytes() const;

private:
    uint64_t flat(int l, int64_t i, int64_t j, int64_t k) const {
        const auto& c = count_[size_t(l)];
        return uint64_t(i + c[0] * (j + c[1] * k));
    }
    Dims dims_;
    int levels_ = 0, branching_ = 2;
    std::vector<std::array<int64_t, 3>> count_;
    std::vector<std::vector<T>> min_, max_;
};

/// Corner source: the dense array (the grid's own data, or the octree tracer reading array data).
template <typename T> struct ArrayCorners {
    VolumeView<T> volume;
    void gather(Coord v, double corner[8]) const {
        const uint64_t base = volume.index(v.x, v.y, v.z);
        const uint64_t sx = 1, sy = volume.dims.x, sz = uint64_t(volume.dims.x) * volume.dims.y;
        corner[0] = double(volume.load(base));
        corner[1] = double(volume.load(base + sx));
        corner[2] = double(volume.load(base + sy));
        corner[3] = double(volume.load(base + sx + sy));
        corner[4] = double(volume.load(base + sz));
        corner[5] = double(volume.load(base + sx + sz));
        corner[6] = double(volume.load(base + sy + sz));
        corner[7] = double(volume.load(base + sx + sy + sz));
    }
};

/// Corner source: an Octree<T>, read the way a grid traversal must without the octree's own
/// walk (Knoll 2006 Sec. 5.3): top-down point location of the cell's lower corner, recording the
/// parent trace, then the other 7 corners by neighbour finding (direct reads inside the same cap
/// or the same scalar leaf).
template <typename T> struct OctreeCorners {
    Octree<T> tree;
    void gather(Coord v, double corner[8]) const {
        uint32_t trace[kMaxDepth];
        const int cap_parents = tree.dmax() - 2;
        int d = 0;
        uint32_t index = 0;
        for (;;) {
            trace[d] = index;
            const InteriorNode<T>& n = tree.node(d, index);
            const int c = octant_of(v, tree.child_bit(d));
            if (n.is_scalar_leaf(c)) {
                // Corners inside the same leaf cube equal its value; the rest are neighbours.
                const double value = double(n.scalar[c]);
                const uint32_t side = tree.child_bit(d), mask = ~(side - 1);
                for (int k = 0; k < 8; ++k) {
                    const Coord dest{v.x + (k & 1), v.y + ((k >> 1) & 1), v.z + ((k >> 2) & 1)};
                    const bool same = ((dest.x & mask) == (v.x & mask)) && ((dest.y & mask) == (v.y & mask)) &&
                                      ((dest.z & mask) == (v.z & mask));
                    corner[k] = same ? value : double(tree.neighbour_find(v, dest, d, trace));
                }
                return;
            }
            if (d == cap_parents) {
                const CapRef<T> cap = tree.cap(index, n, c);
                const int oct = octant_of(v, 1u);
                for (int k = 0; k < 8; ++k) {
                    const int dir = ((k & 1) << 2) | (k & 2) | ((k >> 2) & 1);   // corner i+2j+4k -> octant bits
                    if ((oct & dir) == 0) {
                        corner[k] = double(cap.voxel(oct | dir));
                    } else {
                        const Coord dest{v.x + (k & 1), v.y + ((k >> 1) & 1), v.z + ((k >> 2) & 1)};
                        corner[k] = double(tree.neighbour_find(v, dest, cap_parents, trace));
                    }
                }
                return;
            }
            index = tree.child_index(d, index, n, c);
            ++d;
        }
    }
};

/// MacrocellTracer: first hit of a world ray with the isosurfaces, through a MacrocellGrid<T>
/// (culling) and a corner source (data). Same contract as OctreeTracer::trace: index-space ray,
/// clip to [0, n-1]^3 (render/ray.h), each cell owns [t_in, t_out) (closed at the data exit),
/// first_root<Finder> per cell. Every face time, at every level, is IndexRay::plane_t of an
/// integer plane, the expression the octree walk and the reference use, so the ray is cut at the
/// same t everywhere. Thread-safe: per-ray state lives on the stack. The grid and the corner
/// source must outlive the tracer.
template <typename T, class Finder, class Corners> class MacrocellTracer {
public:
    MacrocellTracer(const MacrocellGrid<T>& grid, const Corners& corners, const Placement& placement,
                    const double* isovalues, int iso_count, const Finder& finder)
        : grid_(grid), corners_(corners), scene_(grid.dims(), placement, isovalues, iso_count), finder_(finder) {
        int64_t s = 1;
        for (int l = 0; l <= grid.levels(); ++l, s *= grid.branching()) unit_[size_t(l)] = double(s);
    }

    TraceHit trace(const Ray& ray_world, bool want_normal) const {
        Walk w;
        const BoxClip clip = w.start(scene_, ray_world, want_normal);
        if (clip.empty()) return w.hit;
        const int top = grid_.levels();
        const int64_t lo[3] = {0, 0, 0};
        const auto& c = grid_.count(top);
        const int64_t hi[3] = {c[0], c[1], c[2]};
        walk(w, top, lo, hi, clip.t_in, clip.t_out);
        return w.hit;
    }

private:
    using Walk = RayState;

    /// DDA over the level-l units [lo, hi) (per axis, hi exclusive) the ray crosses on [t0, t1),
    /// in order; a macrocell is entered when an isovalue lies in its range, a cell is solved.
    /// Unit m of level l spans the index planes [m u, (m+1) u], u = B^l (the one cell DDA,
    /// cell_dda.h; a ray lying in the data's top face takes the last unit of the level).
    bool walk(Walk& w, int l, const int64_t lo[3], const int64_t hi[3], double t0, double t1) const {
        const auto& top = grid_.count(l);
        const DdaBox box{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}, {top[0] - 1, top[1] - 1, top[2] - 1}, scene_.box_hi};
        return walk_units(w.ray, ScaledCells{unit_[size_t(l)]}, box, t0, t1, w.t_exit,
                          [&](const int64_t cell[3], double t_in, double t_out, bool closed_end) {
                              if (l == 0) {
                                  const Coord v{uint32_t(cell[0]), uint32_t(cell[1]), uint32_t(cell[2])};
                                  double corner[8];
                                  corners_.gather(v, corner);
                                  return test_cell(w, v, corner, t_in, t_out, closed_end);
                              }
                              if (!scene_.any_iso_in(double(grid_.min_at(l, cell[0], cell[1], cell[2])),
                                                     double(grid_.max_at(l, cell[0], cell[1], cell[2]))))
                                  return false;
                              const int64_t b = grid_.branching();
                              const auto& below = grid_.count(l - 1);
                              const int64_t clo[3] = {cell[0] * b, cell[1] * b, cell[2] * b};
                              const int64_t chi[3] = {std::min(clo[0] + b, below[0]), std::min(clo[1] + b, below[1]),
                                                      std::min(clo[2] + b, below[2])};
                              return walk(w, l - 1, clo, chi, t_in, t_out);
                          });
    }

    /// An integer grid's cells get the octree's unscaled cubic too (cell.h, IntegerCorners): the
    /// peer in its best configuration, the same roots.
    bool test_cell(Walk& w, Coord v, const double corner[8], double t_in, double t_out, bool closed_end) const {
        return intersect_cell<Finder, false, CornerKindOf<T>>(finder_, scene_, w, v, corner, t_in, t_out, closed_end);
    }

    const MacrocellGrid<T>& grid_;
    const Corners corners_;
    const CellWalkScene scene_;
    const Finder finder_;
    std::array<double, 12> unit_{};   // B^l as double, l = 0 .. levels (<= 10)
};

}  // namespace octiso
