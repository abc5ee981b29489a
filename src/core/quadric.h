// The error quadric of GH97 §4: Q(v) = v^T A v + 2 b^T v + c, the (weighted) sum of squared
// distances from v to a set of planes. Stored as the 10 distinct numbers of the symmetric 4x4
// matrix, plus the total plane weight so that errors can be reported in distance units.
#pragma once

#include "geometry/vec3.h"

namespace qem::core {

struct Quadric {
  // A (symmetric 3x3), b, c: the 10 numbers of GH97 §4.
  double a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0;
  double b0 = 0, b1 = 0, b2 = 0;
  double c = 0;
  /// Sum of the weights of the planes (area, count or angle): Q(v) / weight is a mean squared
  /// distance, which is how errors are reported and how --max-error is interpreted.
  double weight = 0;

  /// The fundamental quadric K_p = w p p^T of the plane n.x + d = 0 (|n| = 1), GH97 §5.
  static Quadric plane(const Vec3& n, double d, double w) {
    Quadric q;
    q.a00 = w * n.x * n.x, q.a01 = w * n.x * n.y, q.a02 = w * n.x * n.z;
    q.a11 = w * n.y * n.y, q.a12 = w * n.y * n.z, q.a22 = w * n.z * n.z;
    q.b0 = w * d * n.x, q.b1 = w * d * n.y, q.b2 = w * d * n.z;
    q.c = w * d * d;
    q.weight = w;
    return q;
  }

  Quadric& operator+=(const Quadric& o) {
    a00 += o.a00, a01 += o.a01, a02 += o.a02, a11 += o.a11, a12 += o.a12, a22 += o.a22;
    b0 += o.b0, b1 += o.b1, b2 += o.b2, c += o.c, weight += o.weight;
    return *this;
  }
  friend Quadric operator+(Quadric a, const Quadric& b) { return a += b; }
  Quadric scaled(double s) const {
    Quadric q = *this;
    q.a00 *= s, q.a01 *= s, q.a02 *= s, q.a11 *= s, q.a12 *= s, q.a22 *= s;
    q.b0 *= s, q.b1 *= s, q.b2 *= s, q.c *= s;
    return q;  // weight unchanged: penalty planes scale the error, not the represented area
  }

  /// A v (the linear part applied to v).
  Vec3 apply_a(const Vec3& v) const {
    return {a00 * v.x + a01 * v.y + a02 * v.z, a01 * v.x + a11 * v.y + a12 * v.z,
            a02 * v.x + a12 * v.y + a22 * v.z};
  }

  /// Delta(v) = v^T A v + 2 b.v + c (GH97 §4). Clamped at 0: rounding can make it slightly negative.
  double evaluate(const Vec3& v) const {
    Vec3 av = apply_a(v);
    double e = dot(v, av) + 2 * (b0 * v.x + b1 * v.y + b2 * v.z) + c;
    return e > 0 ? e : 0;
  }
};

}  // namespace qem::core
