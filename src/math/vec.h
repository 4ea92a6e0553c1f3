// Vector maths on std::array<double, 3>, the one 3-vector type of the world- and index-space
// code (rays, cameras, normals). Plain inline functions: no SIMD types, no allocation.
#pragma once

#include <array>
#include <cmath>
#include <numbers>

namespace octiso {

using Vec3 = std::array<double, 3>;

inline Vec3 vec_sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 vec_cross(const Vec3& a, const Vec3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double vec_dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 vec_normalized(const Vec3& a) {
    const double len = std::sqrt(vec_dot(a, a));
    return {a[0] / len, a[1] / len, a[2] / len};
}
inline double radians_from_degrees(double deg) { return deg * std::numbers::pi / 180.0; }

}  // namespace octiso
