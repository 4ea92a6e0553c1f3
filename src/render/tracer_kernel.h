// TracerKernel: the octree traversal for one (octree, isovalues, root finder), compiled for one
// instruction set and chosen once per process (issue 11: runtime ISA dispatch). The portable
// kernel (kernel_baseline.cpp, the default x86-64-v2 flags) and the AVX2 kernel (kernel_avx2.cpp,
// -mavx2 -mfma -ffp-contract=off) are the same source (kernel_impl.h) in different ISA
// namespaces (util/isa.h). FMA contraction is off, so both do the same IEEE operations in the
// same order: frames are bit-identical across ISAs (tests/render/packet_test.cpp). The renderer only
// sees function pointers, called once per packet of up to kMaxTracePacket rays, never per cell.
#pragma once

#include <memory>
#include <string>

#include "octiso/octree.h"
#include "octiso/render.h"
#include "octiso/volume.h"
#include "render/lod.h"
#include "render/packet_size.h"
#include "scene/embree_scene.h"

namespace octiso {

struct TracerKernel {
    std::shared_ptr<const void> tracer;                 ///< owns the typed tracer `user` points at
    const void* user = nullptr;
    EmbreeVolumeScene::TraceFn trace = nullptr;               ///< one ray
    EmbreeVolumeScene::TracePacketFn trace_packet = nullptr;  ///< up to kMaxTracePacket rays
    /// Level of detail for the next frames (lod.h); between frames only.
    void (*set_lod)(const void* user, const LodCut& cut) = nullptr;
    Isa isa = Isa::baseline;
    std::shared_ptr<const std::vector<double>> ghost_plane;   ///< RenderOptions::ghost_plane, if any
};

// resolve_isa() and cpu_has_avx2() are public (octiso/render.h); defined in kernel_baseline.cpp.

/// The kernel for `options` (isovalues, root finder, iterations, packet threshold) on `tree`,
/// for the instruction set `isa` (resolved: baseline or avx2). The tree's storage must outlive it.
template <typename T> TracerKernel make_tracer_kernel(const Octree<T>& tree, const Placement& placement,
                                                      const RenderOptions& options, Isa isa);

/// The two builds of the same source; make_tracer_kernel picks one.
template <typename T> TracerKernel make_tracer_kernel_baseline(const Octree<T>& tree, const Placement& placement,
                                                               const RenderOptions& options);
template <typename T> TracerKernel make_tracer_kernel_avx2(const Octree<T>& tree, const Placement& placement,
                                                           const RenderOptions& options);

}  // namespace octiso
