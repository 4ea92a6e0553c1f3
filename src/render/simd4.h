// Four doubles per AVX2 register for the AVX2 kernel (kernel_avx2.cpp): the packet split
// (traverse.h, PacketSplit), the beam and the lanes' starts (packet_start.h). GCC vector
// extensions; the operations are the scalar IEEE ones lane by lane (no FMA: -ffp-contract=off),
// so the results are the scalar ones bit for bit. Empty in the portable kernel.
#pragma once

#if defined(__AVX2__)

#include <cstring>

#include "util/isa.h"

namespace octiso {
OCTISO_ISA_BEGIN

using V4d = double __attribute__((vector_size(32)));
using V4l = long long __attribute__((vector_size(32)));
/// What a comparison of two V4d gives (GCC: four longs, -1 where true); V4l(m) converts.
using V4m = decltype(V4d{} < V4d{});
OCTISO_ALWAYS_INLINE void load4(V4d& v, const double* p) { std::memcpy(&v, p, sizeof v); }
OCTISO_ALWAYS_INLINE void store4(double* p, const V4d& v) { std::memcpy(p, &v, sizeof v); }

OCTISO_ISA_END
}  // namespace octiso

#endif
