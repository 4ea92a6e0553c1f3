// Secondary rays of the ray-traced look (issue 17 item 7): shadow rays toward the key light and
// ambient-occlusion rays over the hemisphere of a hit, started a fixed distance off the hit and
// traced by the same exact tracer as the primary rays (any `TraceHit trace(const Ray&, bool)`:
// the TracerKernel in the frame, the dense brute-force tracer in the tests). Through surfaces of
// opacity < 1 a secondary ray continues and carries their transmittance, so a translucent skin
// does not black out the bone it covers. The per-pixel sample sequence is a pure function of the
// pixel, so an image is the same bit for bit on every run and thread count. No allocation.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <span>

#include "math/hit.h"
#include "math/ray.h"
#include "math/vec.h"
#include "octiso/render.h"
#include "render/clip.h"

namespace octiso {

/// Where a secondary ray starts, in voxels (CONVENTIONS 2b: the smallest spacing) past the hit
/// it leaves: t_min of a shadow or AO ray from the hit point, and of the next layer of a
/// composited primary ray past the previous hit. The hit t of the default finder lies within
/// 0.0172 voxel of the exact root in the worst pixel measured over the 230 agreement frames
/// (DepthBar, tests/render/render_test_util.h); a ray started closer than that can re-find its own
/// surface (shadow acne, a layer counted twice). 0.02 voxel clears it; the price is that an
/// occluder or a second surface closer than 0.02 voxel to the hit is not seen.
inline constexpr double kSecondaryOffsetVoxels = 0.02;
/// Composited rays stop once the accumulated opacity reaches this (the rest is below one 8-bit
/// level of the surfaces behind), and secondary rays once their transmittance falls below 1 - it.
inline constexpr double kOpaqueAlpha = 0.995;
/// At most this many surfaces per composited or secondary ray: bounds the cost on noisy data,
/// where a ray can cross hundreds of sheets of a translucent isovalue.
inline constexpr int kMaxLayers = 16;
/// The default reach of an ambient-occlusion ray, in voxels: creases the size of sulci (5-15 mm
/// on the 1 mm ch2better template) darken, the far side of the head does not.
inline constexpr double kDefaultAoDistanceVoxels = 10.0;

/// Counts of one tile's secondary rays: plain locals, folded once per tile.
struct SecondaryCounters {
    uint64_t shadow_rays = 0, ao_rays = 0, layer_rays = 0;   ///< each continuation past a surface counts once
};

/// The opacity of each isovalue (index = TraceHit::iso_index) in [0, 1]; isovalues past the span are opaque.
struct Opacities {
    std::span<const double> alpha;
    double of(int iso) const { return size_t(iso) < alpha.size() ? alpha[size_t(iso)] : 1.0; }
};

/// The world point at distance t along `ray`.
inline Vec3 point_at(const Ray& ray, double t) {
    return {ray.origin[0] + t * ray.dir[0], ray.origin[1] + t * ray.dir[1], ray.origin[2] + t * ray.dir[2]};
}

/// The fraction of light that passes `ray` on its interval: 1 on a miss, the product of
/// (1 - opacity) over the surfaces it crosses, each next one searched from offset past the last
/// (0 at the first opaque one). Adds the continuations to counters.layer_rays. `first`, if given,
/// is the ray's first hit already traced (in a packet), and is not traced again.
template <class Trace>
double transmittance(Trace&& trace, Ray ray, const Opacities& opacity, double offset, SecondaryCounters& counters,
                     const TraceHit* first = nullptr) {
    double pass = 1.0;
    for (int layer = 0; layer < kMaxLayers; ++layer) {
        if (layer > 0) ++counters.layer_rays;
        const TraceHit hit = layer == 0 && first ? *first : trace(ray, false);
        if (!hit.is_hit()) return pass;
        pass *= 1.0 - opacity.of(hit.iso_index);
        if (pass <= 1.0 - kOpaqueAlpha) return 0.0;
        ray.t_min = hit.t + offset;
    }
    return pass;
}

/// The shadow ray of a hit at world point `p`: toward the unit direction `to_light`, from offset
/// to +inf, clipped by the frame's planes (what is cut away casts no shadow).
inline Ray shadow_ray(const Vec3& p, const Vec3& to_light, double offset, std::span<const ClipPlane> clip_planes) {
    Ray r{p, to_light, offset};
    clip_ray(clip_planes, r);
    return r;
}

/// An orthonormal basis (t, b, n) around unit n without a branch on a near-pole cutoff (Duff et
/// al. 2017, "Building an Orthonormal Basis, Revisited", Listing 3).
inline void orthonormal_basis(const Vec3& n, Vec3& t, Vec3& b) {
    const double sign = std::copysign(1.0, n[2]);
    const double a = -1.0 / (sign + n[2]), c = n[0] * n[1] * a;
    t = {1.0 + sign * n[0] * n[0] * a, sign * c, -sign * n[0]};
    b = {c, sign + n[1] * n[1] * a, -n[1]};
}

/// A 32-bit integer hash (Wellons' lowbias32), the per-pixel seed's mixer.
inline uint32_t hash32(uint32_t x) {
    x ^= x >> 16, x *= 0x7feb352dU, x ^= x >> 15, x *= 0x846ca68bU, x ^= x >> 16;
    return x;
}

/// The seed of pixel (px, py) of a frame whose rays are shifted by `pixel_offset` (antialiasing
/// samples get different seeds, so --spp also averages the occlusion noise).
inline uint32_t pixel_seed(int px, int py, const std::array<double, 2>& pixel_offset) {
    uint64_t bits[2];
    std::memcpy(bits, pixel_offset.data(), sizeof bits);
    uint32_t h = hash32(uint32_t(px) * 0x9e3779b9U ^ hash32(uint32_t(py)));
    h = hash32(h ^ uint32_t(bits[0]) ^ uint32_t(bits[0] >> 32));
    return hash32(h ^ uint32_t(bits[1]) ^ uint32_t(bits[1] >> 32));
}

/// The bits of x in reverse order (the base-2 radical inverse of x, times 2^32).
inline uint32_t reverse_bits(uint32_t x) {
    x = (x << 16) | (x >> 16);
    x = ((x & 0x00ff00ffU) << 8) | ((x & 0xff00ff00U) >> 8);
    x = ((x & 0x0f0f0f0fU) << 4) | ((x & 0xf0f0f0f0U) >> 4);
    x = ((x & 0x33333333U) << 2) | ((x & 0xccccccccU) >> 2);
    return ((x & 0x55555555U) << 1) | ((x & 0xaaaaaaaaU) >> 1);
}

/// Sample s of n (0 <= s < n) of a pixel with `seed`, in [0, 1)^2: the Hammersley point
/// ((s + 1/2) / n, radical inverse of s in base 2), shifted modulo 1 by a rotation drawn from the
/// seed (Cranley-Patterson): stratified within the pixel, decorrelated between pixels.
inline std::array<double, 2> ao_sample(int s, int n, uint32_t seed) {
    const double r0 = double(seed >> 8) * 0x1p-24, r1 = double(hash32(seed) >> 8) * 0x1p-24;
    double u0 = (double(s) + 0.5) / double(n) + r0, u1 = double(reverse_bits(uint32_t(s))) * 0x1p-32 + r1;
    u0 -= std::floor(u0), u1 -= std::floor(u1);
    return {u0, u1};
}

/// The ambient-occlusion ray of a hit at `p` with unit normal `n` (facing the viewer) for the
/// sample u in [0, 1)^2: cosine-weighted over the hemisphere of n (Malley's method: a uniform
/// point of the unit disc lifted onto the hemisphere), on [offset, reach], clipped by the planes.
/// Its transmittance averaged over the samples estimates the cosine-weighted unoccluded fraction.
inline Ray ao_ray(const Vec3& p, const Vec3& n, const std::array<double, 2>& u, double offset, double reach,
                  std::span<const ClipPlane> clip_planes) {
    Vec3 t, b;
    orthonormal_basis(n, t, b);
    const double r = std::sqrt(u[0]), phi = 2.0 * std::numbers::pi * u[1];
    const double x = r * std::cos(phi), y = r * std::sin(phi), z = std::sqrt(std::max(0.0, 1.0 - u[0]));
    Ray ray{p, vec_normalized({x * t[0] + y * b[0] + z * n[0], x * t[1] + y * b[1] + z * n[1], x * t[2] + y * b[2] + z * n[2]}),
            offset, reach};
    clip_ray(clip_planes, ray);
    return ray;
}

}  // namespace octiso
