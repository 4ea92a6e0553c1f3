// OCTISO_ALWAYS_INLINE: for the few helpers the traversal kernels call from outside their own
// headers (point location, rays). The kernels are compiled once per instruction set
// (src/util/isa.h); an out-of-line copy of such a helper, shared between those builds by the
// linker, could run AVX2 code on a CPU without it. Forced inline, each build has its own.
#pragma once

#if defined(__GNUC__)
#define OCTISO_ALWAYS_INLINE [[gnu::always_inline]] inline
#define OCTISO_LAMBDA_INLINE __attribute__((always_inline))   ///< after a lambda's parameter list
#else
#define OCTISO_ALWAYS_INLINE inline
#define OCTISO_LAMBDA_INLINE
#endif
