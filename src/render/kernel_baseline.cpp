// The portable traversal kernel: the project's default flags (x86-64-v2). See tracer_kernel.h.
#include "render/kernel_impl.h"

#include <stdexcept>

#include "octiso/error.h"

namespace octiso {

bool cpu_has_avx2() {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
    return false;
#endif
}

Isa resolve_isa(Isa requested) {
    static const bool has_avx2 = cpu_has_avx2();
    switch (requested) {
        case Isa::automatic: return has_avx2 ? Isa::avx2 : Isa::baseline;
        case Isa::baseline: return Isa::baseline;
        case Isa::avx2:
            if (!has_avx2) throw Error("isa", "this CPU lacks AVX2 or FMA; use the baseline kernel");
            return Isa::avx2;
    }
    return Isa::baseline;
}

template <typename T> TracerKernel make_tracer_kernel_baseline(const Octree<T>& tree, const Placement& placement,
                                                               const RenderOptions& options) {
    return build_tracer_kernel(tree, placement, options, Isa::baseline);
}

template <typename T> TracerKernel make_tracer_kernel(const Octree<T>& tree, const Placement& placement,
                                                      const RenderOptions& options, Isa isa) {
    return resolve_isa(isa) == Isa::avx2 ? make_tracer_kernel_avx2(tree, placement, options)
                                         : make_tracer_kernel_baseline(tree, placement, options);
}

#define OCTISO_INSTANTIATE(T)                                                                                      \
    template TracerKernel make_tracer_kernel_baseline<T>(const Octree<T>&, const Placement&, const RenderOptions&); \
    template TracerKernel make_tracer_kernel<T>(const Octree<T>&, const Placement&, const RenderOptions&, Isa);
OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE)
#undef OCTISO_INSTANTIATE

}  // namespace octiso
