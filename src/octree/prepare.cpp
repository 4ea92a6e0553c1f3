// Input conditioning (see prepare.h).
//
// Iso-range clamping, and why it is not a plain clamp: the isosurface inside a cell depends on all
// 8 corners, so clamping one corner of a cell that reaches into (LO,HI) would move that cell's
// surface. A voxel below LO is therefore clamped only when every data cell it is a corner of has
// all 8 corners <= LO, i.e. when every data voxel of its 3x3x3 neighbourhood is <= LO. Such cells
// hold no surface for any iso in (LO,HI), before or after. The 3x3x3 test is a separable AND of
// per-voxel flags, done in place in three passes (x rows, y columns, z columns).
#include "octree/prepare.h"

#include <cmath>
#include <limits>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "octiso/error.h"

namespace octiso::detail {

namespace {

constexpr uint8_t kAtOrBelowLo = 1;
constexpr uint8_t kAtOrAboveHi = 2;

// In-place AND of each element with its neighbours at -stride and +stride along a line of n.
inline void and3_line(uint8_t* p, uint64_t n, uint64_t stride) {
    uint8_t prev = 0xff;
    for (uint64_t i = 0; i < n; ++i) {
        const uint8_t here = p[i * stride];
        const uint8_t next = i + 1 < n ? p[(i + 1) * stride] : uint8_t(0xff);
        p[i * stride] = uint8_t(prev & here & next);
        prev = here;
    }
}

template <typename T> std::string voxel_text(const VolumeView<T>& v, uint64_t i, uint32_t z_first) {
    const uint64_t x = i % v.dims.x, y = (i / v.dims.x) % v.dims.y, z = i / (uint64_t(v.dims.x) * v.dims.y) + z_first;
    return "(" + std::to_string(x) + "," + std::to_string(y) + "," + std::to_string(z) + ")";
}

}  // namespace

template <typename T> T clamp_target_low(double lo) {
    if constexpr (std::is_floating_point_v<T>) {
        T t = T(lo);
        if (double(t) > lo) t = std::nextafter(t, -std::numeric_limits<T>::infinity());
        return t;
    } else {
        const double f = std::floor(lo);
        if (f <= double(std::numeric_limits<T>::lowest())) return std::numeric_limits<T>::lowest();
        if (f >= double(std::numeric_limits<T>::max())) return std::numeric_limits<T>::max();
        return T(f);
    }
}

template <typename T> T clamp_target_high(double hi) {
    if constexpr (std::is_floating_point_v<T>) {
        T t = T(hi);
        if (double(t) < hi) t = std::nextafter(t, std::numeric_limits<T>::infinity());
        return t;
    } else {
        const double c = std::ceil(hi);
        if (c <= double(std::numeric_limits<T>::lowest())) return std::numeric_limits<T>::lowest();
        if (c >= double(std::numeric_limits<T>::max())) return std::numeric_limits<T>::max();
        return T(c);
    }
}

template <typename T>
PreparedVolume<T> prepare_volume(const VolumeView<T>& input, const BuildOptions& options, uint32_t z_first) {
    PreparedVolume<T> out;
    out.view = input;
    const uint64_t n = input.dims.voxels();

    // 1. Non-finite values: find the first one (refuse) or count them (replace).
    if constexpr (std::is_floating_point_v<T>) {
        const uint64_t first_bad = tbb::parallel_reduce(
            tbb::blocked_range<uint64_t>(0, n, 1 << 16), n,
            [&](const tbb::blocked_range<uint64_t>& r, uint64_t best) {
                for (uint64_t i = r.begin(); i < r.end() && i < best; ++i)
                    if (!std::isfinite(input.load(i))) return i;
                return best;
            },
            [](uint64_t a, uint64_t b) { return a < b ? a : b; });
        if (first_bad < n) {
            if (!options.nan_as)
                throw Error(options.source_name, "voxel " + voxel_text(input, first_bad, z_first) + " is " +
                                                     (std::isnan(input.load(first_bad)) ? "NaN" : "infinite") +
                                                     " (pass --nan-as V to replace non-finite values)");
            out.storage.resize(n);
            const T replacement = T(*options.nan_as);
            tbb::parallel_for(tbb::blocked_range<uint64_t>(0, n, 1 << 16), [&](const tbb::blocked_range<uint64_t>& r) {
                for (uint64_t i = r.begin(); i < r.end(); ++i) {
                    const T v = input.load(i);
                    out.storage[i] = std::isfinite(v) ? v : replacement;
                }
            });
            out.view = VolumeView<T>{reinterpret_cast<const std::byte*>(out.storage.data()), input.dims, false};
        }
    }

    // 2. Iso-range clamping (see the file comment).
    if (!options.iso_range) return out;
    const double lo = (*options.iso_range)[0], hi = (*options.iso_range)[1];
    const VolumeView<T> src = out.view;
    const Dims d = src.dims;
    std::vector<uint8_t> flags(n);
    tbb::parallel_for(tbb::blocked_range<uint64_t>(0, n, 1 << 16), [&](const tbb::blocked_range<uint64_t>& r) {
        for (uint64_t i = r.begin(); i < r.end(); ++i) {
            const double v = double(src.load(i));
            flags[i] = uint8_t((v <= lo ? kAtOrBelowLo : 0) | (v >= hi ? kAtOrAboveHi : 0));
        }
    });
    const uint64_t nx = d.x, nxy = uint64_t(d.x) * d.y;
    tbb::parallel_for(uint64_t(0), uint64_t(d.y) * d.z, [&](uint64_t row) { and3_line(&flags[row * nx], d.x, 1); });
    tbb::parallel_for(uint64_t(0), uint64_t(d.z), [&](uint64_t z) {
        for (uint64_t x = 0; x < nx; ++x) and3_line(&flags[z * nxy + x], d.y, nx);
    });
    tbb::parallel_for(uint64_t(0), uint64_t(d.y), [&](uint64_t y) {
        for (uint64_t x = 0; x < nx; ++x) and3_line(&flags[y * nx + x], d.z, nxy);
    });

    const T lo_t = clamp_target_low<T>(lo), hi_t = clamp_target_high<T>(hi);
    std::vector<T> clamped(n);
    tbb::parallel_for(tbb::blocked_range<uint64_t>(0, n, 1 << 16), [&](const tbb::blocked_range<uint64_t>& r) {
        for (uint64_t i = r.begin(); i < r.end(); ++i) {
            T v = src.load(i);
            if ((flags[i] & kAtOrBelowLo) && v < lo_t) v = lo_t;
            else if ((flags[i] & kAtOrAboveHi) && v > hi_t) v = hi_t;
            clamped[i] = v;
        }
    });
    flags = {};
    out.storage = std::move(clamped);
    out.view = VolumeView<T>{reinterpret_cast<const std::byte*>(out.storage.data()), d, false};
    return out;
}

#define OCTISO_INSTANTIATE(T)                                                                  \
    template PreparedVolume<T> prepare_volume<T>(const VolumeView<T>&, const BuildOptions&, uint32_t); \
    template T clamp_target_low<T>(double);                                                   \
    template T clamp_target_high<T>(double);
OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE)
#undef OCTISO_INSTANTIATE

}  // namespace octiso::detail
