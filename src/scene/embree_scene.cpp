#include "scene/embree_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "octiso/error.h"

namespace octiso {

struct ExactRayContext {
    RTCIntersectContext base;   // must come first: Embree hands the callback a pointer to it
    const Ray* rays;            // lane i of the packet (or the single ray) traces rays[i]
    bool want_normal;
    TraceHit hits[EmbreeVolumeScene::kPacket];
};

namespace {

struct VolumeGeometry {
    std::array<double, 3> lo, hi;
    const void* user;
    EmbreeVolumeScene::TraceFn trace;
    EmbreeVolumeScene::TracePacketFn trace_packet;
};

void bounds_callback(const RTCBoundsFunctionArguments* args) {
    const auto* g = static_cast<const VolumeGeometry*>(args->geometryUserPtr);
    // Pad outwards: Embree tests its float copy of the ray against these float bounds before it
    // calls us, and a grazing double ray must not be lost to float rounding. The traversal clips
    // the exact ray to the exact box, so the padding never adds a hit.
    double pad = 0;
    for (int a = 0; a < 3; ++a) pad = std::max(pad, std::max(std::fabs(g->lo[a]), std::fabs(g->hi[a])));
    pad = pad * 1e-5 + 1e-6;
    args->bounds_o->lower_x = float(g->lo[0] - pad);
    args->bounds_o->lower_y = float(g->lo[1] - pad);
    args->bounds_o->lower_z = float(g->lo[2] - pad);
    args->bounds_o->upper_x = float(g->hi[0] + pad);
    args->bounds_o->upper_y = float(g->hi[1] + pad);
    args->bounds_o->upper_z = float(g->hi[2] + pad);
}

void intersect_callback(const RTCIntersectFunctionNArguments* args) noexcept {
    auto* ctx = reinterpret_cast<ExactRayContext*>(args->context);
    const auto* g = static_cast<const VolumeGeometry*>(args->geometryUserPtr);
    const unsigned n = args->N;
    RTCRayN* rays = RTCRayHitN_RayN(args->rayhit, n);
    RTCHitN* hits = RTCRayHitN_HitN(args->rayhit, n);
    const unsigned lanes = std::min(n, unsigned(EmbreeVolumeScene::kPacket));
    TraceHit traced[EmbreeVolumeScene::kPacket];
    if (g->trace_packet && lanes > 1) {
        g->trace_packet(g->user, ctx->rays, int(lanes), args->valid, ctx->want_normal, traced);
    } else {
        for (unsigned i = 0; i < lanes; ++i)
            if (args->valid[i]) traced[i] = g->trace(g->user, ctx->rays[i], ctx->want_normal);
    }
    for (unsigned i = 0; i < lanes; ++i) {
        if (!args->valid[i]) continue;
        const TraceHit& hit = traced[i];
        if (!hit.is_hit() || !(hit.t < ctx->hits[i].t)) continue;
        ctx->hits[i] = hit;
        RTCRayN_tfar(rays, n, i) = float(hit.t);
        RTCHitN_Ng_x(hits, n, i) = float(hit.normal[0]);
        RTCHitN_Ng_y(hits, n, i) = float(hit.normal[1]);
        RTCHitN_Ng_z(hits, n, i) = float(hit.normal[2]);
        RTCHitN_u(hits, n, i) = RTCHitN_v(hits, n, i) = 0;
        RTCHitN_geomID(hits, n, i) = args->geomID;
        RTCHitN_primID(hits, n, i) = args->primID;
        RTCHitN_instID(hits, n, i, 0) = RTC_INVALID_GEOMETRY_ID;
    }
}

void occluded_callback(const RTCOccludedFunctionNArguments* args) noexcept {
    auto* ctx = reinterpret_cast<ExactRayContext*>(args->context);
    const auto* g = static_cast<const VolumeGeometry*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N && i < EmbreeVolumeScene::kPacket; ++i) {
        if (!args->valid[i]) continue;
        const TraceHit hit = g->trace(g->user, ctx->rays[i], false);
        float& tfar = RTCRayN_tfar(args->ray, args->N, i);
        if (hit.is_hit() && hit.t <= tfar) tfar = -INFINITY;   // Embree's "occluded" mark
    }
}

/// The one Embree device of the process, created on first use and shared by every scene: a
/// device starts Embree's internal state once, while scenes are cheap, so a 153-step series or
/// an interactive session pays the device once. Embree devices are thread-safe for creating
/// scenes. Errors land in a per-thread slot that commit() reads.
thread_local std::string t_last_error;

void device_error_callback(void*, RTCError code, const char* message) {
    t_last_error = "Embree error " + std::to_string(int(code)) + (message ? std::string(": ") + message : std::string());
}

RTCDevice shared_device() {
    static const RTCDevice device = [] {
        RTCDevice d = rtcNewDevice(nullptr);
        if (d) rtcSetDeviceErrorFunction(d, device_error_callback, nullptr);
        return d;
    }();
    if (!device) throw Error("embree", "cannot create a device", ErrorKind::Other);
    return device;
}

}  // namespace

struct EmbreeVolumeScene::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<std::unique_ptr<VolumeGeometry>> geometries;
};

EmbreeVolumeScene::EmbreeVolumeScene() : impl_(std::make_unique<Impl>()) {
    impl_->device = shared_device();
    impl_->scene = rtcNewScene(impl_->device);
    if (!impl_->scene) throw Error("embree", "cannot create a scene: " + t_last_error, ErrorKind::Other);
    rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
}

EmbreeVolumeScene::~EmbreeVolumeScene() {
    if (impl_->scene) rtcReleaseScene(impl_->scene);
}

void EmbreeVolumeScene::add_volume(const std::array<double, 3>& lo, const std::array<double, 3>& hi, const void* user,
                                   TraceFn trace, TracePacketFn trace_packet) {
    impl_->geometries.push_back(std::make_unique<VolumeGeometry>(VolumeGeometry{lo, hi, user, trace, trace_packet}));
    RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geom, 1);
    rtcSetGeometryUserData(geom, impl_->geometries.back().get());
    rtcSetGeometryBoundsFunction(geom, bounds_callback, nullptr);
    rtcSetGeometryIntersectFunction(geom, intersect_callback);
    rtcSetGeometryOccludedFunction(geom, occluded_callback);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(impl_->scene, geom);
    rtcReleaseGeometry(geom);
}

void EmbreeVolumeScene::set_volume_trace(size_t index, const void* user, TraceFn trace, TracePacketFn trace_packet) {
    VolumeGeometry& g = *impl_->geometries.at(index);
    g.user = user;
    g.trace = trace;
    g.trace_packet = trace_packet;
}

void EmbreeVolumeScene::commit() {
    t_last_error.clear();
    rtcCommitScene(impl_->scene);
    if (!t_last_error.empty()) throw Error("embree", t_last_error, ErrorKind::Other);
}

TraceHit EmbreeVolumeScene::intersect(const Ray& ray, bool want_normal) const {
    ExactRayContext ctx;
    rtcInitIntersectContext(&ctx.base);
    ctx.rays = &ray;
    ctx.want_normal = want_normal;
    RTCRayHit rh{};
    rh.ray.org_x = float(ray.origin[0]);
    rh.ray.org_y = float(ray.origin[1]);
    rh.ray.org_z = float(ray.origin[2]);
    rh.ray.dir_x = float(ray.dir[0]);
    rh.ray.dir_y = float(ray.dir[1]);
    rh.ray.dir_z = float(ray.dir[2]);
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.mask = 0xffffffffu;   // Debian's Embree is built with ray masks: -1 or nothing hits
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(impl_->scene, &ctx.base, &rh);
    return ctx.hits[0];
}

void EmbreeVolumeScene::intersect_packet(const Ray* rays, int count, bool want_normal, TraceHit* hits) const {
    ExactRayContext ctx;
    rtcInitIntersectContext(&ctx.base);
    ctx.base.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;   // neighbouring pixels of one tile row
    ctx.rays = rays;
    ctx.want_normal = want_normal;
    alignas(32) RTCRayHit8 rh{};
    alignas(32) int valid[kPacket];
    for (int i = 0; i < kPacket; ++i) {
        valid[i] = i < count ? -1 : 0;
        const Ray& r = rays[i < count ? i : 0];
        rh.ray.org_x[i] = float(r.origin[0]);
        rh.ray.org_y[i] = float(r.origin[1]);
        rh.ray.org_z[i] = float(r.origin[2]);
        rh.ray.dir_x[i] = float(r.dir[0]);
        rh.ray.dir_y[i] = float(r.dir[1]);
        rh.ray.dir_z[i] = float(r.dir[2]);
        rh.ray.tnear[i] = 0.0f;
        rh.ray.tfar[i] = std::numeric_limits<float>::infinity();
        rh.ray.mask[i] = 0xffffffffu;
        rh.ray.flags[i] = 0;
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, impl_->scene, &ctx.base, &rh);
    for (int i = 0; i < count; ++i) hits[i] = ctx.hits[i];
}

}  // namespace octiso
