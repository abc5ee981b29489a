// How much an attribute kind counts in the metric (Hoppe 1999's attribute quadric): the weight
// that turns its values into distance units. One table for the core's wedges, the attribute fit
// and the far-place repair, so the three judge the same channels alike.
#pragma once

#include "qem/mesh.h"
#include "qem/simplify.h"

namespace qem::core {

inline double attribute_weight(AttributeKind kind, const AttributeWeights& w) {
  switch (kind) {
    case AttributeKind::Normal: return w.normal;
    case AttributeKind::TexCoord: return w.tex_coord;
    case AttributeKind::Color: return w.color;
    case AttributeKind::Scalar: return w.scalar;
    case AttributeKind::JointIndices:  // ids: never interpolated
    case AttributeKind::JointWeights:  // taken with the joints they weigh
    case AttributeKind::Tangent:       // recomputed from the normals and UVs by renderers
      return 0;
  }
  return 0;
}

}  // namespace qem::core
