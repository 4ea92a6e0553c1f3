// Dense brute-force reference tracer (see brute_force.h): clip to the data box, then a DDA over
// every cell in index space in double. Cell-local segment endpoints are built from the integer
// cell index plus an offset (notes E11), and set exactly to 0 or 1 on the faces the ray crosses,
// so neighbouring cells agree bitwise on shared face values (the half-open rule depends on it).
#include "reference/brute_force.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace octiso {

template <typename T, typename Finder>
RefHit trace_reference(const VolumeView<T>& volume, const Placement& placement, const Ray& ray_world, double iso,
                       const Finder& finder) {
    RefHit hit;
    const Dims dims = volume.dims;
    if (dims.x < 2 || dims.y < 2 || dims.z < 2) return hit;   // no cells (CONVENTIONS 1)
    const int64_t n_cells[3] = {int64_t(dims.x) - 1, int64_t(dims.y) - 1, int64_t(dims.z) - 1};
    const std::array<double, 3> box_hi{double(n_cells[0]), double(n_cells[1]), double(n_cells[2])};

    const IndexRay ray = index_from_world(ray_world, placement);
    const BoxClip clip = clip_to_box(ray, box_hi, ray_world);   // the ray's [t_min, t_max]
    if (clip.empty()) return hit;

    int64_t cell[3];
    std::array<double, 3> p_in_cell, p_out_cell;
    auto local = [&](int a, double t) { return (ray.origin[a] - double(cell[a])) + t * ray.dir[a]; };

    // 1. Entry cell: the one the ray moves into (ceil - 1 when moving down), clamped to the data.
    //    An axis whose slab is entered exactly at t_in sits exactly on the box face.
    for (int a = 0; a < 3; ++a) {
        const double d = ray.dir[a];
        const double boundary = d > 0 ? 0.0 : box_hi[a];
        const bool on_face = d != 0 && ray.plane_t(a, boundary) == clip.t_in;
        const double p = on_face ? boundary : ray.origin[a] + clip.t_in * d;
        const double c = d < 0 ? std::ceil(p) - 1 : std::floor(p);
        cell[a] = std::clamp<int64_t>(int64_t(std::clamp(c, -1.0, box_hi[a])), 0, n_cells[a] - 1);
        p_in_cell[a] = on_face ? boundary - double(cell[a]) : local(a, clip.t_in);
    }

    // 2. Walk: each cell owns [t_cell_in, t_cell_out); faces crossed at the same t step together.
    double t_cell_in = clip.t_in;
    for (;;) {
        double t_next[3];
        for (int a = 0; a < 3; ++a) {
            const double d = ray.dir[a];
            t_next[a] = d > 0 ? ray.plane_t(a, double(cell[a] + 1))
                              : (d < 0 ? ray.plane_t(a, double(cell[a])) : std::numeric_limits<double>::infinity());
        }
        double t_cell_out = std::fmin(std::fmin(t_next[0], t_next[1]), std::fmin(t_next[2], clip.t_out));
        t_cell_out = std::fmax(t_cell_out, t_cell_in);   // rounding never gives a negative length
        bool is_last = t_cell_out >= clip.t_out;
        bool leaves[3];
        for (int a = 0; a < 3; ++a) {
            const double d = ray.dir[a];
            leaves[a] = d != 0 && t_next[a] <= t_cell_out;
            if (leaves[a]) {
                const int64_t next = cell[a] + (d > 0 ? 1 : -1);
                if (next < 0 || next >= n_cells[a]) is_last = true;
                p_out_cell[a] = d > 0 ? 1.0 : 0.0;
            } else {
                p_out_cell[a] = local(a, t_cell_out);
            }
        }

        double corner[8];
        for (int k = 0; k < 2; ++k)
            for (int j = 0; j < 2; ++j)
                for (int i = 0; i < 2; ++i)
                    corner[i + 2 * j + 4 * k] = double(volume.at(uint32_t(cell[0] + i), uint32_t(cell[1] + j),
                                                                 uint32_t(cell[2] + k)));
        const double s = first_root(finder, corner, iso, p_in_cell, p_out_cell, is_last);
        if (s >= 0) {
            hit.t = t_cell_in + s * (t_cell_out - t_cell_in);
            std::array<double, 3> p_hit_cell;
            for (int a = 0; a < 3; ++a) p_hit_cell[a] = p_in_cell[a] + s * (p_out_cell[a] - p_in_cell[a]);
            hit.normal = world_normal(corner, p_hit_cell, placement.spacing, ray_world.dir);
            for (int a = 0; a < 3; ++a) hit.cell[a] = uint32_t(cell[a]);
            return hit;
        }
        if (is_last) return hit;

        for (int a = 0; a < 3; ++a) {
            if (leaves[a]) {
                cell[a] += ray.dir[a] > 0 ? 1 : -1;
                p_in_cell[a] = ray.dir[a] > 0 ? 0.0 : 1.0;
            } else {
                p_in_cell[a] = p_out_cell[a];   // same cell index, same t: bitwise the same point
            }
        }
        t_cell_in = t_cell_out;
    }
}

#define OCTISO_INSTANTIATE_REFERENCE(T)                                                                        \
    template RefHit trace_reference<T, Neubauer>(const VolumeView<T>&, const Placement&, const Ray&, double,  \
                                                 const Neubauer&);                                            \
    template RefHit trace_reference<T, Schwarze>(const VolumeView<T>&, const Placement&, const Ray&, double,  \
                                                 const Schwarze&);                                            \
    template RefHit trace_reference<T, Linear>(const VolumeView<T>&, const Placement&, const Ray&, double,    \
                                               const Linear&);                                                \
    template RefHit trace_reference<T, Exact>(const VolumeView<T>&, const Placement&, const Ray&, double,     \
                                              const Exact&);
OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE_REFERENCE)
#undef OCTISO_INSTANTIATE_REFERENCE

}  // namespace octiso
