// LiveChildren<T>: which children of an interior node may hold an isosurface, for all 8 at once.
// For 1-byte scalars, whose child bounds are stored exact (ChildBounds<T, true>), the isovalues
// become integer thresholds once per tracer and the cull of a node is a few SSE2 byte compares:
// an integer bound lo satisfies lo <= iso exactly when lo <= floor(iso), and hi >= iso exactly
// when hi >= ceil(iso), so the mask is InteriorNode::may_contain_any's answer bit for bit. An
// empty child (min > max) can satisfy neither pair, so it is never live.
// A node with no live child is left before the ray is split at its mid-planes, and only the
// live children are visited: 0.958-0.984 x the frame time (min of 7 interleaved pairs, medians
// 0.957-0.977; build_ab_live_children.json, BENCHMARKS.md packet section). The same mask from a
// plain loop over the 8 children in doubles was slower than the per-child test (1.03-1.06 x at
// the median; build_ab_live_children_double_loop_rerun.json), so wider scalars, whose quantized
// bounds decode through a multiply each, keep the per-child test (may_contain_any): holds() is
// the one predicate the traversal asks, whichever it is.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>   // SSE2 (in every x86-64 build): _mm_max_epu8, _mm_min_epu8, _mm_movemask_epi8
#endif

#include "octiso/limits.h"
#include "octiso/octree.h"
#include "util/isa.h"

namespace octiso {
OCTISO_ISA_BEGIN

template <typename T> class LiveChildren {
public:
    /// Whether of() is the exact cull; where not, it returns all 8 and the caller tests each child.
    static constexpr bool kExact = sizeof(T) == 1;

    LiveChildren(const double* isos, int count) {
        if constexpr (kExact) {
            // Keys: the stored byte, with the sign bit flipped for i8 so that byte order is value order.
            constexpr double lowest = std::is_signed_v<T> ? -128.0 : 0.0;
            for (int i = 0; i < count; ++i) {
                const double lo = std::floor(isos[i]) - lowest, hi = std::ceil(isos[i]) - lowest;
                // lo < 0 only where iso < lowest <= every min, hi > 255 only where iso > highest >=
                // every max: no child holds such an isovalue.
                if (!(lo >= 0 && hi <= 255)) continue;
#if defined(__SSE2__)
                floor_key_[used_] = _mm_set1_epi8(char(uint8_t(lo)));
                ceil_key_[used_] = _mm_set1_epi8(char(uint8_t(hi)));
#else
                floor_key_[used_] = uint8_t(lo), ceil_key_[used_] = uint8_t(hi);
#endif
                ++used_;
            }
        }
    }

    /// Bit c set where child c of `n` may hold an isosurface (kExact), or all 8 bits.
    OCTISO_ALWAYS_INLINE unsigned of(const InteriorNode<T>& n) const {
        if constexpr (!kExact) {
            return 0xFFu;
        } else {
            constexpr uint8_t kSign = std::is_signed_v<T> ? 0x80 : 0;
#if defined(__SSE2__)
            const __m128i flip = _mm_set1_epi8(char(kSign));
            uint64_t lo_bytes, hi_bytes;
            std::memcpy(&lo_bytes, n.bounds.min, 8);
            std::memcpy(&hi_bytes, n.bounds.max, 8);
            const __m128i lo = _mm_xor_si128(_mm_cvtsi64_si128(int64_t(lo_bytes)), flip);
            const __m128i hi = _mm_xor_si128(_mm_cvtsi64_si128(int64_t(hi_bytes)), flip);
            __m128i any = _mm_setzero_si128();
            for (int i = 0; i < used_; ++i) {
                // lo <= a  <=>  max(lo, a) == a;  hi >= b  <=>  min(hi, b) == b.
                const __m128i a = floor_key_[i], b = ceil_key_[i];
                const __m128i below = _mm_cmpeq_epi8(_mm_max_epu8(lo, a), a);
                const __m128i above = _mm_cmpeq_epi8(_mm_min_epu8(hi, b), b);
                any = _mm_or_si128(any, _mm_and_si128(below, above));
            }
            return unsigned(_mm_movemask_epi8(any)) & 0xFFu;
#else
            unsigned live = 0;
            for (int c = 0; c < 8; ++c) {
                const uint8_t lo = uint8_t(n.bounds.min[c]) ^ kSign, hi = uint8_t(n.bounds.max[c]) ^ kSign;
                for (int i = 0; i < used_; ++i)
                    live |= unsigned(lo <= floor_key_[i] && hi >= ceil_key_[i]) << c;
            }
            return live;
#endif
        }
    }

    /// Whether child c of `n` may hold an isosurface, given live = of(n): the mask where it is
    /// exact, else the per-child test. The one cull predicate of the traversal.
    OCTISO_ALWAYS_INLINE static bool holds(const InteriorNode<T>& n, unsigned live, int c, const double* isos,
                                           int count) {
        if constexpr (kExact) return (live >> c) & 1u;
        else return n.may_contain_any(c, isos, count);
    }

private:
    // floor(iso) and ceil(iso) as keys, one per isovalue inside the type's range: in all 16 bytes
    // of a register where SSE2 compares them, else as bytes.
#if defined(__SSE2__)
    __m128i floor_key_[kMaxIsovalues];
    __m128i ceil_key_[kMaxIsovalues];
#else
    uint8_t floor_key_[kMaxIsovalues] = {};
    uint8_t ceil_key_[kMaxIsovalues] = {};
#endif
    int used_ = 0;
};

OCTISO_ISA_END
}  // namespace octiso
