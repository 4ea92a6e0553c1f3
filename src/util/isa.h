// The instruction-set namespace of the hot traversal code (issue 11: runtime ISA dispatch). The
// traversal headers (render/traverse.h, cell.h, cell_hit.h, cell_dda.h, roots.h) put everything in
// `octiso::OCTISO_ISA_NAMESPACE`, an inline namespace: callers still write octiso::Foo, but each
// translation unit compiled for another instruction set (render/kernel_avx2.cpp, built with
// -DOCTISO_ISA_NAMESPACE=isa_avx2 -mavx2 -mfma) gets its own mangled names. Without it the linker
// would keep one copy of every inline function and template instantiation, and could hand AVX2
// code to the portable path (an illegal instruction on an older CPU) or the reverse.
// The few inline helpers outside these headers that the traversal calls (IndexRay, clip_to_box,
// Octree's point location) are forced inline (OCTISO_ALWAYS_INLINE), so no out-of-line copy is
// shared either; scripts/check_isa.py checks the built tools for VEX code outside isa_avx2.
#pragma once

#ifndef OCTISO_ISA_NAMESPACE
#define OCTISO_ISA_NAMESPACE isa_baseline
#endif

#define OCTISO_ISA_BEGIN inline namespace OCTISO_ISA_NAMESPACE {
#define OCTISO_ISA_END }

#include "octiso/inline.h"   // OCTISO_ALWAYS_INLINE
