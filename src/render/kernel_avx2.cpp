// The AVX2 traversal kernel: this file alone is compiled with -mavx2 -mfma -ffp-contract=off and
// -DOCTISO_ISA_NAMESPACE=isa_avx2 (src/CMakeLists.txt), so its code runs only where
// resolve_isa() found AVX2 and FMA, and its arithmetic equals the baseline's bit for bit (no
// contraction into FMA). See tracer_kernel.h.
#include "render/kernel_impl.h"

namespace octiso {

template <typename T> TracerKernel make_tracer_kernel_avx2(const Octree<T>& tree, const Placement& placement,
                                                           const RenderOptions& options) {
    return build_tracer_kernel(tree, placement, options, Isa::avx2);
}

#define OCTISO_INSTANTIATE(T) \
    template TracerKernel make_tracer_kernel_avx2<T>(const Octree<T>&, const Placement&, const RenderOptions&);
OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE)
#undef OCTISO_INSTANTIATE

}  // namespace octiso
