// Building the macrocell grid (see macrocell.h): level 1 from the voxels of each block of B^3 cells
// plus its forward layer, every higher level from the B^3 ranges below it (exact: the union of the
// children's cells is the parent's cells). Levels are filled in parallel over z-slabs with TBB.
#include "reference/macrocell.h"

#include <tbb/parallel_for.h>

#include "octiso/error.h"

namespace octiso {

template <typename T>
MacrocellGrid<T>::MacrocellGrid(const VolumeView<T>& volume, const MacrocellOptions& options)
    : dims_(volume.dims), levels_(options.levels), branching_(options.branching) {
    if (branching_ < 2 || branching_ > 64)
        throw Error("--branching", "expected 2 .. 64 cells per macrocell edge, found " + std::to_string(branching_));
    if (levels_ < 0 || levels_ > 10)
        throw Error("--levels", "expected 0 .. 10 macrocell levels, found " + std::to_string(levels_));
    const int64_t b = branching_;
    count_.resize(size_t(levels_) + 1);
    min_.resize(size_t(levels_) + 1);
    max_.resize(size_t(levels_) + 1);
    const int64_t n_cells[3] = {std::max<int64_t>(int64_t(dims_.x) - 1, 1), std::max<int64_t>(int64_t(dims_.y) - 1, 1),
                                std::max<int64_t>(int64_t(dims_.z) - 1, 1)};
    count_[0] = {n_cells[0], n_cells[1], n_cells[2]};
    for (int l = 1; l <= levels_; ++l)
        for (int a = 0; a < 3; ++a) count_[size_t(l)][a] = (count_[size_t(l) - 1][a] + b - 1) / b;
    if (dims_.x < 2 || dims_.y < 2 || dims_.z < 2) {   // no cells: every range empty
        for (int l = 1; l <= levels_; ++l) {
            const auto& c = count_[size_t(l)];
            min_[size_t(l)].assign(size_t(c[0] * c[1] * c[2]), std::numeric_limits<T>::max());
            max_[size_t(l)].assign(size_t(c[0] * c[1] * c[2]), std::numeric_limits<T>::lowest());
        }
        return;
    }

    for (int l = 1; l <= levels_; ++l) {
        const auto c = count_[size_t(l)];
        auto& mn = min_[size_t(l)];
        auto& mx = max_[size_t(l)];
        mn.assign(size_t(c[0] * c[1] * c[2]), std::numeric_limits<T>::max());
        mx.assign(size_t(c[0] * c[1] * c[2]), std::numeric_limits<T>::lowest());
        const auto below = count_[size_t(l) - 1];
        tbb::parallel_for(int64_t(0), c[2], [&](int64_t k) {
            for (int64_t j = 0; j < c[1]; ++j)
                for (int64_t i = 0; i < c[0]; ++i) {
                    T lo = std::numeric_limits<T>::max(), hi = std::numeric_limits<T>::lowest();
                    bool any = false;
                    const int64_t m[3] = {i, j, k};
                    int64_t from[3], to[3];   // children [from, to) of the level below
                    for (int a = 0; a < 3; ++a) from[a] = m[a] * b, to[a] = std::min(from[a] + b, below[a]);
                    if (l == 1) {
                        // Cells [from, to) have corners [from, to] (the forward layer).
                        for (int64_t z = from[2]; z <= to[2]; ++z)
                            for (int64_t y = from[1]; y <= to[1]; ++y)
                                for (int64_t x = from[0]; x <= to[0]; ++x) {
                                    const T v = volume.at(uint32_t(x), uint32_t(y), uint32_t(z));
                                    if constexpr (std::is_floating_point_v<T>)
                                        if (!std::isfinite(v)) continue;
                                    lo = std::min(lo, v), hi = std::max(hi, v), any = true;
                                }
                    } else {
                        for (int64_t z = from[2]; z < to[2]; ++z)
                            for (int64_t y = from[1]; y < to[1]; ++y)
                                for (int64_t x = from[0]; x < to[0]; ++x) {
                                    const T cl = min_at(l - 1, x, y, z), ch = max_at(l - 1, x, y, z);
                                    if (cl > ch) continue;   // empty child
                                    lo = std::min(lo, cl), hi = std::max(hi, ch), any = true;
                                }
                    }
                    if (any) mn[flat(l, i, j, k)] = lo, mx[flat(l, i, j, k)] = hi;
                }
        });
    }
}

template <typename T> uint64_t MacrocellGrid<T>::bytes() const {
    uint64_t n = 0;
    for (int l = 1; l <= levels_; ++l) n += uint64_t(min_[size_t(l)].size() + max_[size_t(l)].size()) * sizeof(T);
    return n;
}

#define OCTISO_INSTANTIATE(T) template class MacrocellGrid<T>;
OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE)
#undef OCTISO_INSTANTIATE

}  // namespace octiso
