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
    const Ray* ray;
    bool want_normal;
    TraceHit hit;
};

namespace {

struct VolumeGeometry {
    std::array<double, 3> lo, hi;
    const void* user;
    EmbreeVolumeScene::TraceFn trace;
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
    if (args->N != 1 || !args->valid[0]) return;
    auto* ctx = reinterpret_cast<ExactRayContext*>(args->context);
    const auto* g = static_cast<const VolumeGeometry*>(args->geometryUserPtr);
    RTCRayHit* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
    const TraceHit hit = g->trace(g->user, *ctx->ray, ctx->want_normal);
    if (!hit.is_hit() || !(hit.t < ctx->hit.t)) return;
    ctx->hit = hit;
    rh->ray.tfar = float(hit.t);
    rh->hit.Ng_x = float(hit.normal[0]);
    rh->hit.Ng_y = float(hit.normal[1]);
    rh->hit.Ng_z = float(hit.normal[2]);
    rh->hit.u = rh->hit.v = 0;
    rh->hit.geomID = args->geomID;
    rh->hit.primID = args->primID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

void occluded_callback(const RTCOccludedFunctionNArguments* args) noexcept {
    if (args->N != 1 || !args->valid[0]) return;
    auto* ctx = reinterpret_cast<ExactRayContext*>(args->context);
    const auto* g = static_cast<const VolumeGeometry*>(args->geometryUserPtr);
    const TraceHit hit = g->trace(g->user, *ctx->ray, false);
    RTCRay* ray = reinterpret_cast<RTCRay*>(args->ray);
    if (hit.is_hit() && hit.t <= ray->tfar) ray->tfar = -INFINITY;   // Embree's "occluded" mark
}

void error_callback(void* user, RTCError code, const char* message) {
    auto* last = static_cast<std::string*>(user);
    *last = "Embree error " + std::to_string(int(code)) + (message ? std::string(": ") + message : std::string());
}

}  // namespace

struct EmbreeVolumeScene::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<std::unique_ptr<VolumeGeometry>> geometries;
    std::string last_error;
};

EmbreeVolumeScene::EmbreeVolumeScene() : impl_(std::make_unique<Impl>()) {
    impl_->device = rtcNewDevice(nullptr);
    if (!impl_->device) throw Error("embree", "cannot create a device", ErrorKind::Other);
    rtcSetDeviceErrorFunction(impl_->device, error_callback, &impl_->last_error);
    impl_->scene = rtcNewScene(impl_->device);
    rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
}

EmbreeVolumeScene::~EmbreeVolumeScene() {
    if (impl_->scene) rtcReleaseScene(impl_->scene);
    if (impl_->device) rtcReleaseDevice(impl_->device);
}

void EmbreeVolumeScene::add_volume(const std::array<double, 3>& lo, const std::array<double, 3>& hi, const void* user,
                                   TraceFn trace) {
    impl_->geometries.push_back(std::make_unique<VolumeGeometry>(VolumeGeometry{lo, hi, user, trace}));
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

void EmbreeVolumeScene::commit() {
    rtcCommitScene(impl_->scene);
    if (!impl_->last_error.empty()) throw Error("embree", impl_->last_error, ErrorKind::Other);
}

TraceHit EmbreeVolumeScene::intersect(const Ray& ray, bool want_normal) const {
    ExactRayContext ctx;
    rtcInitIntersectContext(&ctx.base);
    ctx.ray = &ray;
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
    return ctx.hit;
}

}  // namespace octiso
