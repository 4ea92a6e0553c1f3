// Names, sizes and parsing of the scalar types of CONVENTIONS 1, and the checked arithmetic on
// grid sizes that every reader relies on before it trusts a number taken from a file.
#include <charconv>
#include <limits>

#include "octiso/error.h"
#include "octiso/volume.h"

namespace octiso {

namespace {
constexpr std::string_view kNames[kScalarTypeCount] = {"u8", "i8", "u16", "i16", "u32", "i32", "f32", "f64"};
constexpr size_t kBytes[kScalarTypeCount] = {1, 1, 2, 2, 4, 4, 4, 8};
}  // namespace

std::string_view scalar_type_name(ScalarType t) { return kNames[size_t(t) % kScalarTypeCount]; }

std::optional<ScalarType> parse_scalar_type(std::string_view name) {
    for (int i = 0; i < kScalarTypeCount; ++i)
        if (kNames[i] == name) return ScalarType(i);
    return std::nullopt;
}

size_t scalar_type_bytes(ScalarType t) { return kBytes[size_t(t) % kScalarTypeCount]; }

Dims parse_dims(std::string_view text, const std::string& flag) {
    uint64_t v[3] = {0, 0, 0};
    const char* p = text.data();
    const char* end = text.data() + text.size();
    for (int i = 0; i < 3; ++i) {
        auto [next, ec] = std::from_chars(p, end, v[i]);
        if (ec != std::errc() || v[i] == 0 || v[i] > Dims::kMaxExtent)
            throw Error(flag, "expected three integers in [1, " + std::to_string(Dims::kMaxExtent) +
                                  "] as NX,NY,NZ, found '" + std::string(text) + "'");
        p = next;
        if (i < 2) {
            if (p == end || *p != ',') throw Error(flag, "expected NX,NY,NZ, found '" + std::string(text) + "'");
            ++p;
        }
    }
    if (p != end) throw Error(flag, "expected NX,NY,NZ, found '" + std::string(text) + "'");
    return Dims{uint32_t(v[0]), uint32_t(v[1]), uint32_t(v[2])};
}

uint64_t checked_volume_bytes(Dims dims, ScalarType type, const std::string& subject) {
    // Extents are <= 2^30 each, so x*y fits in 64 bits; the last two products need checking.
    uint64_t n = uint64_t(dims.x) * dims.y;
    uint64_t bytes = 0;
    if (__builtin_mul_overflow(n, uint64_t(dims.z), &n) ||
        __builtin_mul_overflow(n, uint64_t(scalar_type_bytes(type)), &bytes))
        throw Error(subject, "volume " + std::to_string(dims.x) + "x" + std::to_string(dims.y) + "x" +
                                 std::to_string(dims.z) + " of " + std::string(scalar_type_name(type)) +
                                 " overflows a 64-bit byte count");
    return bytes;
}

}  // namespace octiso
