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

/// 1-byte scalars (format 6, CapAnchor in octree.h): picks the anchor and width of a cap parent
/// whose bounds are set, widens bounds that miss a voxel of their cap (the last data layer) and
/// gives a cap child with no cells empty bounds its deltas fit; then packs each cap as a 64-bit
/// word of 8 deltas, byte 0 into the slot, the b - 1 others into `out`. Returns n (b - 1).
template <typename T> uint64_t pack_anchored_caps(InteriorNode<T>& node, const Cap<T>* caps, int n, uint8_t* out) {
    static_assert(sizeof(T) == 1);
    using K = ScalarKey<T>;
    int child[8];
    uint8_t key[8][8];    // per cap, per voxel
    uint8_t base[2][8];   // per anchor, per cap: the key of its base
    unsigned width[2] = {1, 1};
    for (int c = 0, j = 0; c < 8; ++c) {
        if (node.is_scalar_leaf(c)) continue;
        child[j] = c;
        uint8_t lo = 255, hi = 0;
        for (int k = 0; k < 8; ++k) {
            key[j][k] = K::of(caps[j].voxel[k]);
            lo = std::min(lo, key[j][k]), hi = std::max(hi, key[j][k]);
        }
        if (!node.bounds.empty(c)) {
            base[0][j] = std::min(K::of(node.bounds.min[c]), lo);
            base[1][j] = std::max(K::of(node.bounds.max[c]), hi);
        } else {
            // No cells: empty bounds whose end is the base (min = base, max = base - 1 for a lower
            // anchor; max = base, min = base + 1 for an upper one); the cap's own range where it can.
            base[0][j] = std::max(lo, uint8_t(1));
            base[1][j] = std::min(hi, uint8_t(254));
        }
        for (int k = 0; k < 8; ++k) {
            width[0] = std::max(width[0], unsigned(std::bit_width(unsigned(uint8_t(key[j][k] - base[0][j])))));
            width[1] = std::max(width[1], unsigned(std::bit_width(unsigned(uint8_t(base[1][j] - key[j][k])))));
        }
        ++j;
    }
    const int a = width[1] < width[0] ? 1 : 0;   // the narrower; lower on a tie
    const unsigned bits = width[a], record = bits - 1;
    node.cap_bits = cap_bits_of(bits, CapAnchor(a));
    std::memset(out, 0, uint64_t(n) * record + kCapReadSlack);
    for (int j = 0; j < n; ++j) {
        const int c = child[j];
        const uint8_t b = base[a][j];
        if (!node.bounds.empty(c)) {
            (a ? node.bounds.max[c] : node.bounds.min[c]) = K::value(b);
        } else {
            node.bounds.min[c] = K::value(a ? uint8_t(b + 1) : b);
            node.bounds.max[c] = K::value(a ? b : uint8_t(b - 1));
        }
        // Delta k at bits [k b, (k+1) b), counted up from the lowest value the deltas reach.
        const uint8_t from = uint8_t(a ? b - ((1u << bits) - 1u) : b);
        uint64_t word = 0;
        for (int k = 0; k < 8; ++k) word |= uint64_t(uint8_t(key[j][k] - from)) << (k * bits);
        node.scalar[c] = K::value(uint8_t(word));
        const uint64_t rest = word >> 8;
        std::memcpy(out + uint64_t(j) * record, &rest, record);
    }
    return uint64_t(n) * record;
}

/// Packs the `n` caps of a cap parent (its stored children in rank order) into `out`, which has
/// room for n * kWholeCapBits<T> bytes plus kCapReadSlack; node.bounds must be set. Wider
/// scalars: sets scalar[c] of each cap child to its base and node.cap_bits; 1-byte ones:
/// pack_anchored_caps. Returns the bytes written (n * cap_record_bytes()).
template <typename T> uint64_t pack_caps(InteriorNode<T>& node, const Cap<T>* caps, int n, uint8_t* out) {
    if constexpr (sizeof(T) == 1) {
        return pack_anchored_caps(node, caps, n, out);
    } else {
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
}

}  // namespace octiso::detail
