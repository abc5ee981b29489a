// The one 3-vector of qem: the simplifier's working positions and quadric algebra (GH97 §4), the
// measure's and the refit's closest points, the renderer's camera. Every operation is written out
// component by component in a fixed order and nothing is reassociated, so a result is the same to
// the last bit wherever it is computed: the golden checksums of the simplifier's output rely on it.
#pragma once

#include <cmath>

namespace qem {

struct Vec3 {
  double x = 0, y = 0, z = 0;
  Vec3() = default;
  Vec3(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}
  /// Component i (0: x, 1: y, 2: z), for loops over the axes.
  double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
};

inline Vec3 operator+(const Vec3& a, const Vec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(const Vec3& a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline Vec3 operator*(double s, const Vec3& a) { return {s * a.x, s * a.y, s * a.z}; }
/// Divides each component (correctly rounded, unlike a * (1 / s)).
inline Vec3 operator/(const Vec3& a, double s) { return {a.x / s, a.y / s, a.z / s}; }

inline double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(const Vec3& a) { return std::sqrt(dot(a, a)); }
/// a scaled to unit length; the zero vector (no direction) when its length is 0 or NaN.
inline Vec3 normalized(const Vec3& a) {
  const double l = length(a);
  return l > 0 ? a * (1 / l) : Vec3{0, 0, 0};
}

}  // namespace qem
