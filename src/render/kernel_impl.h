// The body of make_tracer_kernel_<isa> (tracer_kernel.h), included by exactly one translation
// unit per instruction set: the OctreeTracer for the options' root finder, owned by the kernel,
// and the two entry points the renderer and the Embree scene call. Everything this includes from
// render/ lives in the ISA namespace of the including unit (util/isa.h).
#pragma once

#include <memory>
#include <type_traits>

#include "render/tracer_kernel.h"
#include "render/traverse.h"

namespace octiso {
OCTISO_ISA_BEGIN

template <typename T> TracerKernel build_tracer_kernel(const Octree<T>& tree, const Placement& placement,
                                                       const RenderOptions& options, Isa isa) {
    return dispatch_root_finder(options.root_finder, options.iterations, [&](const auto& finder) {
        // Two tracers: the sort-last one (owned cells, RenderOptions::owned_cells) only when asked,
        // so the default kernel carries none of its tests (traverse.h, kOwned).
        const auto build = [&](auto owned) {
            using Tracer = OctreeTracer<T, std::decay_t<decltype(finder)>, OctreeCornerSource, NoRecorder, decltype(owned)::value>;
            auto tracer = std::make_shared<Tracer>(tree, placement, options.isovalues.data(), int(options.isovalues.size()),
                                                   finder);
            if (options.packet_min_lanes > 0) tracer->set_min_packet_lanes(options.packet_min_lanes);
            if constexpr (decltype(owned)::value)
                tracer->set_owned_cells(*options.owned_cells, options.ghost_plane ? options.ghost_plane->data() : nullptr);
            TracerKernel k;
            k.user = tracer.get();
            k.ghost_plane = options.ghost_plane;   // the tracer reads it: kept alive with the kernel
            k.tracer = std::move(tracer);
            k.isa = isa;
            k.trace = [](const void* user, const Ray& ray, bool normal) {
                return static_cast<const Tracer*>(user)->trace(ray, normal);
            };
            k.set_lod = [](const void* user, const LodCut& cut) { static_cast<const Tracer*>(user)->set_lod(cut); };
            k.trace_packet = [](const void* user, const Ray* rays, int count, const int* valid, bool normal, TraceHit* hits) {
                static_cast<const Tracer*>(user)->trace_packet(rays, count, valid, normal, hits);
            };
            return k;
        };
        return options.owned_cells ? build(std::true_type{}) : build(std::false_type{});
    });
}

OCTISO_ISA_END
}  // namespace octiso
