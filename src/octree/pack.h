// Packing into the compact node layout (octree.h, issue 19): conservative 8-bit child bounds and
// caps as deltas from a base. The builders (summary.h) call these as each node is finished, so no
// wide copy of the tree is ever held. Each code is chosen by running the reader's own decode
// (ChildBounds::decode), so the bounds contain the true range bit for bit on every ISA.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "octiso/octree.h"
#include "util/check.h"

namespace octiso::detail {

/// Bounds of 8 children whose exact cell ranges are [mn[c], mx[c]] (mn > mx: empty).
template <typename T> ChildBounds<T> pack_bounds(const T (&mn)[8], const T (&mx)[8]) {
    ChildBounds<T> b;
    if constexpr (sizeof(T) == 1) {
        std::copy(mn, mn + 8, b.min);
        std::copy(mx, mx + 8, b.max);
    } else {
        constexpr int top = ChildBounds<T>::kTop;
        bool any = false;
        T lo = std::numeric_limits<T>::max(), hi = std::numeric_limits<T>::lowest();
        for (int c = 0; c < 8; ++c)
            if (mn[c] <= mx[c]) any = true, lo = std::min(lo, mn[c]), hi = std::max(hi, mx[c]);
        b.lo = any ? lo : T{};
        b.hi = any ? hi : T{};
        const double s = b.step(), width = double(b.hi) - double(b.lo);
        for (int c = 0; c < 8; ++c) {
            if (!(mn[c] <= mx[c])) {
                b.qmin[c] = uint8_t(top), b.qmax[c] = 0;
                continue;
            }
            const double a = double(mn[c]), z = double(mx[c]);
            // A first guess from the real quotient, then the decode itself decides.
            auto guess = [&](double v, bool up) {
                if (!(width > 0) || !std::isfinite(width)) return up ? top : 0;
                const double g = (v - double(b.lo)) / width * top;
                const double r = up ? std::ceil(g) : std::floor(g);
                return int(std::clamp(r, 0.0, double(top)));
            };
            int ql = guess(a, false), qh = guess(z, true);
            while (ql > 0 && b.decode_lower(ql, s) > a) --ql;
            while (ql < top && b.decode_lower(ql + 1, s) <= a) ++ql;
            while (qh < top && b.decode_upper(qh, s) < z) ++qh;
            while (qh > 0 && b.decode_upper(qh - 1, s) >= z) --qh;
            if (ql > qh) ql = 0, qh = top;   // a plateau of the decode (lo == hi): the node's own range
            OCTISO_DCHECK(b.decode_lower(ql, s) <= a && z <= b.decode_upper(qh, s) && ql <= qh, "bounds code of child ", c);
            b.qmin[c] = uint8_t(ql), b.qmax[c] = uint8_t(qh);
        }
    }
    return b;
}

/// Packs the `n` caps of a cap parent (its stored children in rank order) into `out`, which has
/// room for n * kWholeCapBits<T> bytes plus kCapReadSlack: sets scalar[c] of each cap child to its
/// base and node.cap_bits; returns the bytes written (n * cap_bits).
template <typename T> uint64_t pack_caps(InteriorNode<T>& node, const Cap<T>* caps, int n, uint8_t* out) {
    using K = ScalarKey<T>;
    typename K::Key base[8] = {};
    unsigned bits = 0;
    for (int j = 0; j < n; ++j) {
        typename K::Key lo = K::of(caps[j].voxel[0]), hi = lo;
        for (int k = 1; k < 8; ++k) lo = std::min(lo, K::of(caps[j].voxel[k])), hi = std::max(hi, K::of(caps[j].voxel[k]));
        base[j] = lo;
        bits = std::max(bits, unsigned(std::bit_width(uint64_t(hi - lo))));
    }
    if (bits > kMaxDeltaBits<T>) bits = kWholeCapBits<T>;
    node.cap_bits = uint8_t(bits);
    int j = 0;
    for (int c = 0; c < 8; ++c)
        if (!node.is_scalar_leaf(c)) node.scalar[c] = K::value(base[j++]);
    OCTISO_DCHECK(j == n, "cap parent with ", j, " stored children and ", n, " caps");
    const uint64_t bytes = uint64_t(n) * bits;
    if (bits == kWholeCapBits<T>) {
        std::memcpy(out, caps, bytes);
        return bytes;
    }
    std::memset(out, 0, bytes + kCapReadSlack);
    for (j = 0; j < n; ++j)
        for (int k = 0; k < 8; ++k) {
            const uint64_t delta = uint64_t(K::of(caps[j].voxel[k]) - base[j]);
            const uint64_t pos = uint64_t(j) * bits * 8 + uint64_t(k) * bits;
            uint64_t word;
            std::memcpy(&word, out + (pos >> 3), 8);
            word |= delta << (pos & 7);
            std::memcpy(out + (pos >> 3), &word, 8);
        }
    return bytes;
}

}  // namespace octiso::detail
