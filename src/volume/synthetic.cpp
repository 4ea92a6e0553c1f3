// The synthetic generators of synthetic.h: each is a small functor giving the natural value of a
// voxel, filled row by row in parallel with TBB and converted to T once. Randomness comes from
// our own 64-bit hash (value noise, fractal sums), so the output never depends on a library's
// random distributions or on the thread count. The plume and mixing fields skip their noise far
// from the interface using exact bounds on the noise, so the skip never changes a value.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "octiso/error.h"
#include "octiso/synthetic.h"

namespace octiso {

namespace {

// ---- hashing and value noise -------------------------------------------------------------

uint64_t mix64(uint64_t z) {   // the splitmix64 finaliser: a bijection with good avalanche
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

uint64_t hash3(int64_t x, int64_t y, int64_t z, uint64_t seed) {
    return mix64(uint64_t(x) * 0x9e3779b97f4a7c15ull ^ uint64_t(y) * 0xc2b2ae3d27d4eb4full ^
                 uint64_t(z) * 0x165667b19e3779f9ull ^ mix64(seed));
}

double unit(uint64_t h) { return double(h >> 11) * 0x1.0p-53; }   // [0, 1)

double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }   // C2 quintic

/// Value noise in [0, 1]: hashed lattice values, quintic-weighted trilinear blend.
double value_noise(double x, double y, double z, uint64_t seed) {
    const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
    const int64_t ix = int64_t(fx), iy = int64_t(fy), iz = int64_t(fz);
    const double u = fade(x - fx), v = fade(y - fy), w = fade(z - fz);
    double c[2][2][2];
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
            for (int d = 0; d < 2; ++d) c[a][b][d] = unit(hash3(ix + a, iy + b, iz + d, seed));
    auto lerp = [](double p, double q, double t) { return p + (q - p) * t; };
    const double x00 = lerp(c[0][0][0], c[1][0][0], u), x10 = lerp(c[0][1][0], c[1][1][0], u);
    const double x01 = lerp(c[0][0][1], c[1][0][1], u), x11 = lerp(c[0][1][1], c[1][1][1], u);
    return lerp(lerp(x00, x10, v), lerp(x01, x11, v), w);
}

/// Fractal sum of `octaves` value-noise octaves (frequency x2, amplitude x0.5), in [0, 1].
double fbm(double x, double y, double z, int octaves, uint64_t seed) {
    double sum = 0, amp = 1, norm = 0, f = 1;
    for (int o = 0; o < octaves; ++o) {
        sum += amp * value_noise(x * f, y * f, z * f, seed + uint64_t(o) * 0x51ed27ull);
        norm += amp;
        amp *= 0.5;
        f *= 2;
    }
    return sum / norm;
}

/// Octaves from base frequency `base` (cycles per unit length) until the wavelength drops below
/// ~3 voxels of a grid whose unit length spans `voxels_per_unit` voxels: detail down to the grid.
int octaves_for(double base, double voxels_per_unit) {
    int n = 1;
    for (double f = base; n < 10 && voxels_per_unit / (2 * f) >= 3.0; f *= 2) ++n;
    return n;
}

double smoothstep(double e0, double e1, double x) {
    const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3 - 2 * t);
}

double centre(uint32_t n) { return 0.5 * double(n - 1); }

// ---- generators: natural value of voxel (x, y, z) ------------------------------------------

struct Sphere {
    double cx, cy, cz;
    explicit Sphere(Dims d) : cx(centre(d.x)), cy(centre(d.y)), cz(centre(d.z)) {}
    double operator()(uint32_t x, uint32_t y, uint32_t z) const {
        const double dx = x - cx, dy = y - cy, dz = z - cz;
        return std::sqrt(dx * dx + dy * dy + dz * dz);
    }
};

// Marschner & Lobb 1994: rho = (1 - sin(pi z/2) + alpha (1 + rho_r(r))) / (2 (1 + alpha)),
// rho_r(r) = cos(2 pi fM cos(pi r / 2)), r = sqrt(x^2 + y^2), sampled on [-1,1]^3.
struct MarschnerLobb {
    Dims d;
    static constexpr double kAlpha = 0.25, kFm = 6.0;
    static double coord(uint32_t i, uint32_t n) { return n > 1 ? -1.0 + 2.0 * i / double(n - 1) : 0.0; }
    double operator()(uint32_t i, uint32_t j, uint32_t k) const {
        constexpr double pi = std::numbers::pi;
        const double x = coord(i, d.x), y = coord(j, d.y), z = coord(k, d.z);
        const double rho_r = std::cos(2 * pi * kFm * std::cos(pi * std::sqrt(x * x + y * y) / 2));
        return (1 - std::sin(pi * z / 2) + kAlpha * (1 + rho_r)) / (2 * (1 + kAlpha));
    }
};

// Menger sponge of the deepest level whose smallest hole still spans a voxel on every axis.
struct Sponge {
    Dims d;
    int levels = 1;
    uint64_t cells = 3;   // 3^levels
    explicit Sponge(Dims dims) : d(dims) {
        const uint32_t m = std::min({dims.x, dims.y, dims.z});
        while (cells * 3 <= m && levels < 19) {
            cells *= 3;
            ++levels;
        }
    }
    double operator()(uint32_t x, uint32_t y, uint32_t z) const {
        uint64_t c[3] = {uint64_t(x) * cells / d.x, uint64_t(y) * cells / d.y, uint64_t(z) * cells / d.z};
        for (int l = 0; l < levels; ++l) {
            int middles = 0;
            for (uint64_t& v : c) {
                middles += (v % 3 == 1);
                v /= 3;
            }
            if (middles >= 2) return 0.0;
        }
        return 255.0;
    }
};

struct Noise {
    double inv;   // 1 / voxels per unit
    explicit Noise(Dims d) : inv(1.0 / std::max(1u, d.max_extent())) {}
    double operator()(uint32_t x, uint32_t y, uint32_t z) const {
        // Smooth octaves (features 1/8 of the grid and finer) plus white noise per voxel.
        const double p = 8 * inv;
        const double smooth = fbm(x * p, y * p, z * p, 5, 0x6e6f697365ull);
        const double white = unit(hash3(x, y, z, 0x7768697465ull));
        return 255.0 * (0.5 * smooth + 0.5 * white);
    }
};

// A buoyant plume rising from a nozzle at the bottom (z up) into still ambient air (exactly 0).
// Its radius grows with height and carries a turbulent, multi-octave wrinkle that grows from a
// laminar base; temperature is hottest (saturated, 255) in the lower core, cools with height
// and radius, fluctuates inside, and is quantized to integers. Step k advects the turbulence
// upward and swirls it, so consecutive steps are similar but not equal.
struct Plume {
    double cx, cy, scale_xy, nz1, aspect, advect, swirl_c, swirl_s;
    int oct_wrinkle, oct_fine;
    static constexpr double kR0 = 0.12, kGrowth = 0.42, kWrinkle = 0.5;
    Plume(Dims d, uint32_t k) {
        cx = centre(d.x);
        cy = centre(d.y);
        scale_xy = 1.0 / std::max(1.0, double(std::max(d.x, d.y) - 1));   // unit = grid width
        nz1 = std::max(1.0, double(d.z - 1));
        aspect = nz1 * scale_xy;   // height of the domain in width units
        advect = 0.045 * k;
        const double a = 0.06 * k;
        swirl_c = std::cos(a);
        swirl_s = std::sin(a);
        const double vox = std::max(d.x, d.y);
        oct_wrinkle = std::min(5, octaves_for(3, vox));
        oct_fine = octaves_for(6, vox);
    }
    double operator()(uint32_t x, uint32_t y, uint32_t z) const {
        const double u = (x - cx) * scale_xy, v = (y - cy) * scale_xy, h = z / nz1;   // h in [0,1]
        const double rr = std::sqrt(u * u + v * v);
        const double radius = kR0 + kGrowth * h;
        const double turb = smoothstep(0.02, 0.45, h);
        // The wrinkle fbm lies in [0,1], so the displaced radius never exceeds this bound.
        const double max_radius = radius * (1 + kWrinkle * turb);
        if (rr >= max_radius) return 0.0;

        // Turbulence lives in a frame that rises and swirls with time.
        const double su = swirl_c * u - swirl_s * v, sv = swirl_s * u + swirl_c * v;
        const double qz = h * aspect - advect;
        const double wrinkle = fbm(su * 3, sv * 3, qz * 3, oct_wrinkle, 0x706c756d65ull);
        const double r_local = radius * (1 + kWrinkle * turb * (2 * wrinkle - 1));
        if (rr >= r_local) return 0.0;
        const double s = rr / r_local;   // 0 on the axis, 1 at the interface

        const double fine = fbm(su * 6 + 17.0, sv * 6, qz * 6, oct_fine, 0x666c616d65ull);
        const double t_max = 255.0 * (1.7 - 1.1 * h);                // cools with height
        double t = t_max * (1 - s * s) * (1 + 0.8 * turb * (fine - 0.5));
        // Entrained ambient pockets: weak mixture drops to ambient, like a flame front.
        if (t < 12.0) return 0.0;
        return std::round(std::min(255.0, t));
    }
};

// Richtmyer-Meshkov-like mixing layer: heavy fluid (255) below a perturbed interface, light
// fluid (0) above. The interface height carries a few large hashed modes plus fractal detail;
// inside a band around it the mixture fraction follows the mean profile plus 3-D turbulent
// fluctuations, sharpened into blobs (bubbles and spikes) and quantized to integers.
struct Mixing {
    uint32_t nx = 0;
    double nz1, scale;
    int oct_blob;
    std::vector<double> eta_;   // interface offset per (x, y) column: it does not depend on z
    static constexpr double kBand = 0.2, kAmp = 0.1;
    explicit Mixing(Dims d) : nx(d.x) {
        const double inv_x = 1.0 / std::max(1.0, double(d.x - 1)), inv_y = 1.0 / std::max(1.0, double(d.y - 1));
        nz1 = std::max(1.0, double(d.z - 1));
        scale = double(d.max_extent());
        oct_blob = octaves_for(8, scale);
        const int oct_surface = std::min(6, octaves_for(4, scale));
        double phase[6][2];
        for (int m = 0; m < 6; ++m)
            for (int a = 0; a < 2; ++a) phase[m][a] = 2 * std::numbers::pi * unit(hash3(m, a, 0, 0x726d69ull));
        eta_.resize(uint64_t(d.x) * d.y);
        tbb::parallel_for(uint32_t(0), d.y, [&](uint32_t y) {
            for (uint32_t x = 0; x < d.x; ++x) eta_[uint64_t(y) * d.x + x] = eta(x * inv_x, y * inv_y, phase, oct_surface);
        });
    }
    // Interface height offset in [-kAmp, kAmp]: a few large modes (weights sum to < 0.43) plus
    // fractal roughness (weight 0.57), both bounded by their weights.
    static double eta(double u, double v, const double (&phase)[6][2], int octaves) {
        constexpr double tau = 2 * std::numbers::pi;
        double e = 0, w = 0.18;
        for (int m = 0; m < 6; ++m, w *= 0.62) {
            const double f = double(2 << (m / 2)) + (m % 2);   // 2,3,4,5,8,9 cycles per width
            e += w * std::cos(tau * f * u + phase[m][0]) * std::cos(tau * f * v + phase[m][1]);
        }
        e += 0.57 * (2 * fbm(u * 6, v * 6, 0.5, octaves, 0x657461ull) - 1);
        return kAmp * e;
    }
    double operator()(uint32_t x, uint32_t y, uint32_t z) const {
        const double h = z / nz1;
        const double zeta_max = kAmp + kBand;   // |eta| <= kAmp, so far voxels need no noise
        if (h <= 0.5 - zeta_max) return 255.0;
        if (h >= 0.5 + zeta_max) return 0.0;
        const double zeta = (h - 0.5 - eta_[uint64_t(y) * nx + x]) / kBand;   // -1 .. 1 across the band
        if (zeta <= -1) return 255.0;
        if (zeta >= 1) return 0.0;
        // Blobs are isotropic in voxels: sample the noise in units of the largest extent.
        const double b = 8.0 / scale;
        const double blob = fbm(x * b, y * b, z * b, oct_blob, 0x626c6f62ull);
        double c = 0.5 - 0.5 * zeta + 1.1 * (blob - 0.5) * (1 - zeta * zeta);
        c = smoothstep(0.2, 0.8, c);   // late-time mixing: sharp-edged blobs of nearly pure fluid
        return std::round(255.0 * c);
    }
};

// A CT-like head in Hounsfield units (issue 19's noisy i16 test volume, like the paper's CThead):
// air (-1000) around an ellipsoidal head of soft tissue (40) over a skull of dense bone
// (1100-1700, porous inside) around a brain (grey/white 30-45) with two CSF ventricles (5).
// Borders blur over about a voxel (partial volume) and every voxel carries scanner noise of
// about 12 HU (a sum of three hashed uniforms), so, as in a real scan, almost nothing merges.
struct CtHead {
    double c[3], inv[3];   // centre and 1 / semi-axes, in voxels
    double vox;            // voxels per unit of the normalised radius (for the blur)
    explicit CtHead(Dims d) {
        const double n[3] = {double(d.x), double(d.y), double(d.z)};
        const double semi[3] = {0.40 * n[0], 0.46 * n[1], 0.42 * n[2]};
        for (int a = 0; a < 3; ++a) c[a] = 0.5 * (n[a] - 1), inv[a] = 1.0 / semi[a];
        vox = std::min({semi[0], semi[1], semi[2]});
    }
    double operator()(uint32_t x, uint32_t y, uint32_t z) const {
        const double p[3] = {(x - c[0]) * inv[0], (y - c[1]) * inv[1], (z - c[2]) * inv[2]};
        const double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        const double w = 1.0 / vox;   // one voxel in normalised radius
        auto inside = [&](double edge) { return smoothstep(edge + w, edge - w, r); };
        const double porous = fbm(x * 0.08, y * 0.08, z * 0.08, 3, 0x626f6e65ull);
        const double bone = 1100 + 600 * porous;
        const double grey = fbm(x * 0.03, y * 0.03, z * 0.03, 3, 0x627261696eull);
        double brain = 30 + 15 * grey;
        for (double side : {-0.18, 0.18}) {   // ventricles: small ellipsoids beside the midline
            const double q[3] = {(p[0] - side) / 0.12, p[1] / 0.30, (p[2] - 0.05) / 0.15};
            const double rv = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
            brain += (5 - brain) * smoothstep(1 + 3 * w, 1 - 3 * w, rv);
        }
        double v = -1000;
        v += (40 - v) * inside(1.0);      // skin and soft tissue
        v += (bone - v) * inside(0.93);   // skull
        v += (brain - v) * inside(0.86);  // brain
        const double noise = unit(hash3(x, y, z, 0x6374a)) + unit(hash3(x, y, z, 0x6374b)) + unit(hash3(x, y, z, 0x6374c));
        return v + 24.0 * (noise - 1.5);   // sigma = 24 / 2 = 12 HU
    }
};

// ---- names, conversion, parallel fill ------------------------------------------------------

enum class Gen { sphere, marschner_lobb, sponge, noise, plume, mixing, plume_series, ct_head };

struct GenInfo {
    Gen gen;
    const char* name;
    ScalarType default_type;
    double int_scale;
};

constexpr GenInfo kGens[] = {
    {Gen::sphere, "sphere", ScalarType::f32, 1.0},
    {Gen::marschner_lobb, "marschner-lobb", ScalarType::f32, 255.0},
    {Gen::sponge, "sponge", ScalarType::u8, 1.0},
    {Gen::noise, "noise", ScalarType::u8, 1.0},
    {Gen::plume, "plume", ScalarType::u8, 1.0},
    {Gen::mixing, "mixing", ScalarType::u8, 1.0},
    {Gen::plume_series, "plume-series", ScalarType::u8, 1.0},
    {Gen::ct_head, "ct-head", ScalarType::i16, 1.0},
};

const GenInfo* find_gen(std::string_view name) {
    if (name == "sierpinski") name = "sponge";
    if (name == "ml") name = "marschner-lobb";
    for (const GenInfo& g : kGens)
        if (name == g.name) return &g;
    return nullptr;
}

const GenInfo& gen_or_throw(std::string_view name, const std::string& subject) {
    if (const GenInfo* g = find_gen(name)) return *g;
    std::string known;
    for (const GenInfo& g : kGens) known += std::string(known.empty() ? "" : ", ") + g.name;
    throw Error(subject, "unknown synthetic volume '" + std::string(name) + "' (known: " + known + ")");
}

template <typename T> T convert(double v, double int_scale) {
    if constexpr (std::is_floating_point_v<T>) {
        return T(v);
    } else {
        const double s = std::round(v * int_scale);
        const double lo = double(std::numeric_limits<T>::lowest()), hi = double(std::numeric_limits<T>::max());
        return T(std::clamp(s, lo, hi));
    }
}

template <typename T, typename G> void fill(std::vector<T>& out, Dims d, const G& g, double int_scale) {
    const uint64_t rows = uint64_t(d.y) * d.z;
    tbb::parallel_for(tbb::blocked_range<uint64_t>(0, rows, 16), [&](const tbb::blocked_range<uint64_t>& r) {
        for (uint64_t row = r.begin(); row != r.end(); ++row) {
            const uint32_t y = uint32_t(row % d.y), z = uint32_t(row / d.y);
            T* dst = out.data() + row * d.x;
            for (uint32_t x = 0; x < d.x; ++x) dst[x] = convert<T>(g(x, y, z), int_scale);
        }
    });
}

std::string dims_text(Dims d) {
    return std::to_string(d.x) + "," + std::to_string(d.y) + "," + std::to_string(d.z);
}

}  // namespace

SyntheticSpec parse_synthetic(std::string_view text, const std::string& flag) {
    const size_t colon = text.find(':');
    if (colon == std::string_view::npos)
        throw Error(flag, "expected NAME:N or NAME:NX,NY,NZ, found '" + std::string(text) + "'");
    const GenInfo& g = gen_or_throw(text.substr(0, colon), flag);

    std::vector<uint64_t> v;
    std::string_view rest = text.substr(colon + 1);
    for (;;) {
        const size_t comma = rest.find(',');
        const std::string_view part = rest.substr(0, comma);
        uint64_t n = 0;
        auto [p, ec] = std::from_chars(part.data(), part.data() + part.size(), n);
        if (ec != std::errc() || p != part.data() + part.size() || n == 0)
            throw Error(flag, "expected positive integers after '" + std::string(g.name) + ":', found '" +
                                  std::string(text) + "'");
        v.push_back(n);
        if (comma == std::string_view::npos) break;
        rest = rest.substr(comma + 1);
    }

    SyntheticSpec spec;
    spec.name = g.name;
    const bool series = g.gen == Gen::plume_series;
    if (series && (v.size() == 2 || v.size() == 4)) {
        spec.steps = v.back() > UINT32_MAX ? UINT32_MAX : uint32_t(v.back());
        v.pop_back();
    } else if (series) {
        throw Error(flag, "expected plume-series:N,STEPS or plume-series:NX,NY,NZ,STEPS, found '" + std::string(text) + "'");
    }
    if (v.size() == 1) v = {v[0], v[0], v[0]};
    if (v.size() != 3) throw Error(flag, "expected NAME:N or NAME:NX,NY,NZ, found '" + std::string(text) + "'");
    for (uint64_t n : v)
        if (n > Dims::kMaxExtent)
            throw Error(flag, "extent " + std::to_string(n) + " exceeds " + std::to_string(Dims::kMaxExtent));
    spec.dims = Dims{uint32_t(v[0]), uint32_t(v[1]), uint32_t(v[2])};
    return spec;
}

std::vector<std::string> synthetic_names() {
    std::vector<std::string> out;
    for (const GenInfo& g : kGens) out.emplace_back(g.name);
    return out;
}

ScalarType synthetic_default_type(std::string_view name) { return gen_or_throw(name, "--synthetic").default_type; }

template <typename T> std::vector<T> generate_synthetic(std::string_view name, Dims dims, uint32_t k) {
    const GenInfo& g = gen_or_throw(name, "--synthetic");
    if (dims.x == 0 || dims.y == 0 || dims.z == 0) throw Error("--synthetic", "dims " + dims_text(dims) + " have a zero extent");
    const uint64_t bytes = checked_volume_bytes(dims, scalar_type_of<T>(), "--synthetic");
    if (bytes / sizeof(T) > std::vector<T>().max_size()) throw Error("--synthetic", "volume too large for memory", ErrorKind::Other);
    std::vector<T> out(dims.voxels());
    switch (g.gen) {
        case Gen::sphere: fill(out, dims, Sphere(dims), g.int_scale); break;
        case Gen::marschner_lobb: fill(out, dims, MarschnerLobb{dims}, g.int_scale); break;
        case Gen::sponge: fill(out, dims, Sponge(dims), g.int_scale); break;
        case Gen::noise: fill(out, dims, Noise(dims), g.int_scale); break;
        case Gen::plume:
        case Gen::plume_series: fill(out, dims, Plume(dims, k), g.int_scale); break;
        case Gen::mixing: fill(out, dims, Mixing(dims), g.int_scale); break;
        case Gen::ct_head: fill(out, dims, CtHead(dims), g.int_scale); break;
    }
    return out;
}

LoadedVolume synthetic_step(std::string_view name, Dims dims, uint32_t k, std::optional<ScalarType> type) {
    const GenInfo& g = gen_or_throw(name, "--synthetic");
    const ScalarType t = type.value_or(g.default_type);
    std::string source = std::string(g.name) + ":" + dims_text(dims) + (k > 0 ? "@" + std::to_string(k) : "");
    return dispatch_scalar_type(t, [&](auto tag) {
        using T = decltype(tag);
        auto voxels = std::make_shared<std::vector<T>>(generate_synthetic<T>(g.name, dims, k));
        const auto* data = reinterpret_cast<const std::byte*>(voxels->data());
        return LoadedVolume(std::shared_ptr<const void>(voxels, voxels.get()), data, t, dims, Placement{}, false,
                            std::move(source), VolumeFormat::synthetic);
    });
}

LoadedVolume make_synthetic(const SyntheticSpec& spec, std::optional<ScalarType> type) {
    return synthetic_step(spec.name, spec.dims, 0, type);
}

template std::vector<uint8_t> generate_synthetic<uint8_t>(std::string_view, Dims, uint32_t);
template std::vector<int8_t> generate_synthetic<int8_t>(std::string_view, Dims, uint32_t);
template std::vector<uint16_t> generate_synthetic<uint16_t>(std::string_view, Dims, uint32_t);
template std::vector<int16_t> generate_synthetic<int16_t>(std::string_view, Dims, uint32_t);
template std::vector<uint32_t> generate_synthetic<uint32_t>(std::string_view, Dims, uint32_t);
template std::vector<int32_t> generate_synthetic<int32_t>(std::string_view, Dims, uint32_t);
template std::vector<float> generate_synthetic<float>(std::string_view, Dims, uint32_t);
template std::vector<double> generate_synthetic<double>(std::string_view, Dims, uint32_t);

}  // namespace octiso
