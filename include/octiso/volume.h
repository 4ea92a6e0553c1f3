// Volumes as the rest of octiso sees them: the scalar types of CONVENTIONS 1, grid dimensions
// with overflow-checked voxel counts, world placement (spacing, origin), and VolumeView<T>, a
// non-owning x-fastest view over raw bytes (mmap'd file or VTK buffer) that may need byte swaps.
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>

namespace octiso {

/// Stored scalar types; the numeric values are part of the .oct format (never renumber).
enum class ScalarType : uint8_t { u8 = 0, i8 = 1, u16 = 2, i16 = 3, u32 = 4, i32 = 5, f32 = 6, f64 = 7 };
inline constexpr int kScalarTypeCount = 8;

std::string_view scalar_type_name(ScalarType t);
std::optional<ScalarType> parse_scalar_type(std::string_view name);   ///< "u8" .. "f64"
size_t scalar_type_bytes(ScalarType t);

template <typename T> constexpr ScalarType scalar_type_of() {
    if constexpr (std::is_same_v<T, uint8_t>) return ScalarType::u8;
    else if constexpr (std::is_same_v<T, int8_t>) return ScalarType::i8;
    else if constexpr (std::is_same_v<T, uint16_t>) return ScalarType::u16;
    else if constexpr (std::is_same_v<T, int16_t>) return ScalarType::i16;
    else if constexpr (std::is_same_v<T, uint32_t>) return ScalarType::u32;
    else if constexpr (std::is_same_v<T, int32_t>) return ScalarType::i32;
    else if constexpr (std::is_same_v<T, float>) return ScalarType::f32;
    else { static_assert(std::is_same_v<T, double>, "unsupported scalar type"); return ScalarType::f64; }
}

/// Applies M to each stored scalar type: explicit instantiations in the .cpp files that own a
/// template write `OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE)` instead of eight lines.
#define OCTISO_FOR_EACH_SCALAR_TYPE(M) M(uint8_t) M(int8_t) M(uint16_t) M(int16_t) M(uint32_t) M(int32_t) M(float) M(double)

/// The single runtime-to-template switch: calls f(T{}) with the C++ type of `t`.
template <typename F> decltype(auto) dispatch_scalar_type(ScalarType t, F&& f) {
    switch (t) {
        case ScalarType::u8: return f(uint8_t{});
        case ScalarType::i8: return f(int8_t{});
        case ScalarType::u16: return f(uint16_t{});
        case ScalarType::i16: return f(int16_t{});
        case ScalarType::u32: return f(uint32_t{});
        case ScalarType::i32: return f(int32_t{});
        case ScalarType::f32: return f(float{});
        case ScalarType::f64: break;
    }
    return f(double{});
}

/// Grid size in voxels. Each extent is in [1, kMaxExtent] (2^30). voxels() can overflow 64 bits
/// (2^90 at most): call it only on dims that passed checked_volume_bytes (every reader does).
struct Dims {
    uint32_t x = 0, y = 0, z = 0;
    static constexpr uint32_t kMaxExtent = 1u << 30;   // keeps N = 2^dmax representable in uint32
    uint64_t voxels() const { return uint64_t(x) * y * z; }
    uint32_t max_extent() const { return x > y ? (x > z ? x : z) : (y > z ? y : z); }
    bool operator==(const Dims&) const = default;
};

/// A half-open box of cells in index space: cell (i, j, k), the one whose lower corner is voxel
/// (i, j, k), is inside when lo <= (i, j, k) < hi on every axis.
struct CellBox {
    std::array<uint32_t, 3> lo{}, hi{};
    bool empty() const { return !(lo[0] < hi[0] && lo[1] < hi[1] && lo[2] < hi[2]); }
    bool operator==(const CellBox&) const = default;
};

/// Parses "NX,NY,NZ"; throws Error(flag, ...) on anything but three integers in [1, kMaxExtent].
Dims parse_dims(std::string_view text, const std::string& flag);
/// Byte count of dims x scalar size; throws Error(subject, ...) if it overflows 64 bits.
uint64_t checked_volume_bytes(Dims dims, ScalarType type, const std::string& subject);

/// World placement: voxel (i,j,k) sits at origin + (i*SX, j*SY, k*SZ) (CONVENTIONS 1).
struct Placement {
    std::array<double, 3> spacing{1.0, 1.0, 1.0};
    std::array<double, 3> origin{0.0, 0.0, 0.0};
};

/// How stored values map to the real values users give and read (NIfTI scl_slope/scl_inter,
/// CONVENTIONS 2b): real = stored * slope + inter. The octree keeps the stored type; isovalues,
/// ranges and --iso-range are real values, turned into stored ones at the tools' edge. The
/// mapping is affine, so the trilinear interpolant commutes with it and {real f = V} is exactly
/// {stored f = stored(V)}. Invariant: slope finite and non-zero, inter finite.
struct ValueScale {
    double slope = 1.0, inter = 0.0;
    bool is_identity() const { return slope == 1.0 && inter == 0.0; }
    double real(double stored) const { return is_identity() ? stored : stored * slope + inter; }
    double stored(double real) const { return is_identity() ? real : (real - inter) / slope; }
    /// A [lo, hi] range mapped either way, still ordered (a negative slope swaps its ends).
    std::array<double, 2> real_range(const std::array<double, 2>& s) const { return ordered(real(s[0]), real(s[1])); }
    std::array<double, 2> stored_range(const std::array<double, 2>& r) const { return ordered(stored(r[0]), stored(r[1])); }
    bool operator==(const ValueScale&) const = default;

private:
    static std::array<double, 2> ordered(double a, double b) { return a <= b ? std::array<double, 2>{a, b} : std::array<double, 2>{b, a}; }
};

/// Axes of the source file that run opposite to the tree's (bit a for axis a = x, y, z): a NIfTI
/// axis whose affine entry is negative is reversed at conversion, so that spacing stays positive
/// (CONVENTIONS 2b), and recorded so that extraction can give the file's order back.
inline constexpr uint8_t kAllAxesFlipped = 7;

/// Placement limits (issue 18): every spacing in [kMinSpacing, kMaxSpacing] (normal, with a
/// normal square), every corner of the world box within +-kMaxWorldCoordinate (squared distances
/// in camera framing and ray set-up stay finite), and voxels no smaller than 2^-40 of the box's
/// largest coordinate (so that origin + i*spacing tells neighbouring voxels apart).
inline constexpr double kMinSpacing = 1e-150, kMaxSpacing = 1e150, kMaxWorldCoordinate = 1e150;
/// Throws Error(subject, ...) (bad input) unless `placement` of a `dims` grid is within those
/// limits; `hint` is appended to the message (e.g. "; override it with --spacing").
void check_placement(const Placement& placement, Dims dims, const std::string& subject, const std::string& hint = "");

/// Non-owning x-fastest view of NX*NY*NZ scalars of type T, starting at `data`. The bytes may be
/// unaligned (raw files with --offset) and of the other endianness (swap_bytes), so every load
/// goes through memcpy; for aligned native data that compiles to a plain load.
template <typename T> struct VolumeView {
    const std::byte* data = nullptr;
    Dims dims;
    bool swap_bytes = false;

    uint64_t index(uint32_t x, uint32_t y, uint32_t z) const {
        return uint64_t(x) + uint64_t(dims.x) * (uint64_t(y) + uint64_t(dims.y) * z);
    }
    T load(uint64_t i) const {
        T v;
        std::memcpy(&v, data + i * sizeof(T), sizeof(T));
        if (swap_bytes) v = byte_swapped(v);
        return v;
    }
    T at(uint32_t x, uint32_t y, uint32_t z) const { return load(index(x, y, z)); }

    static T byte_swapped(T v) {
        if constexpr (sizeof(T) == 1) {
            return v;
        } else {
            using U = std::conditional_t<sizeof(T) == 2, uint16_t, std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>;
            U u;
            std::memcpy(&u, &v, sizeof(T));
            if constexpr (sizeof(T) == 2) u = __builtin_bswap16(u);
            else if constexpr (sizeof(T) == 4) u = __builtin_bswap32(u);
            else u = __builtin_bswap64(u);
            std::memcpy(&v, &u, sizeof(T));
            return v;
        }
    }
};

}  // namespace octiso
