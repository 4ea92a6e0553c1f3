// EmbreeVolumeScene: an Embree 3 scene with one user geometry per volume, whose bounds are the
// volume's data box in world space and whose intersect callback runs the octree traversal.
// Primary rays go through rtcIntersect8 (packets of 4x2 pixels) or rtcIntersect1. Embree's RTCRay holds floats, so the exact double ray
// travels beside it in an extended intersect context; the callback traces that one, and the
// Embree and direct paths return bit-identical hits.
#pragma once

#include <array>
#include <cstddef>
#include <memory>

#include "math/hit.h"
#include "math/ray.h"

namespace octiso {

/// The double-precision ray and the full hit record, carried through Embree to the callback.
struct ExactRayContext;

class EmbreeVolumeScene {
public:
    /// A function that traces `ray` and returns the hit; `user` is the traced object.
    using TraceFn = TraceHit (*)(const void* user, const Ray& ray, bool want_normal);
    /// Traces rays[0 .. count) at once (count <= kPacket; lanes with valid[k] == 0 are skipped)
    /// into hits: Embree's intersectN callback hands its whole packet to it (issue 11).
    using TracePacketFn = void (*)(const void* user, const Ray* rays, int count, const int* valid, bool want_normal,
                                   TraceHit* hits);

    EmbreeVolumeScene();
    ~EmbreeVolumeScene();
    EmbreeVolumeScene(const EmbreeVolumeScene&) = delete;
    EmbreeVolumeScene& operator=(const EmbreeVolumeScene&) = delete;

    /// Adds a volume whose world bounds are [lo, hi]; `user` must outlive the scene.
    /// `trace_packet` may be null (then each lane is traced alone).
    void add_volume(const std::array<double, 3>& lo, const std::array<double, 3>& hi, const void* user, TraceFn trace,
                    TracePacketFn trace_packet = nullptr);
    /// Points volume `index` (in add_volume order) at another traced object; bounds stay. Not
    /// while a ray of this scene is in flight.
    void set_volume_trace(size_t index, const void* user, TraceFn trace, TracePacketFn trace_packet = nullptr);
    void commit();
    /// First hit of `ray` (world, unit direction) over all geometries. Thread-safe after commit().
    TraceHit intersect(const Ray& ray, bool want_normal) const;
    /// The same for up to kPacket rays at once (rtcIntersect8): one Embree call per packet shares
    /// the dispatch cost that dominates rtcIntersect1 on a scene of one user geometry.
    static constexpr int kPacket = 8;
    void intersect_packet(const Ray* rays, int count, bool want_normal, TraceHit* hits) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace octiso
