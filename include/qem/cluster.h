// Uniform vertex clustering (Rossignac & Borrel 1993), the baseline GH97 §2 compares against
// (GH97 Fig. 15): a grid over the bounding box, every cell's vertices merge into one representative,
// and faces with two or more corners in one cell vanish. The representative minimises the cluster's
// summed face quadrics (Lindstrom 2000, "Out-of-core simplification of large polygonal models").
#pragma once

#include "qem/mesh.h"

namespace qem {

/// Where a cluster's representative vertex goes.
enum class ClusterPlacement {
  Quadric,  ///< minimiser of the summed area-weighted face quadrics, mean along ill-conditioned axes
  Mean,     ///< mean of the cluster's vertices (Rossignac & Borrel use a weighted "important" vertex)
};

struct ClusterOptions {
  /// Cells per axis over the bounding box; used when all three are > 0.
  int grid[3] = {0, 0, 0};
  /// Otherwise: the edge length of cubic cells, absolute or (cell_relative) times the bbox diagonal.
  double cell = 0;
  bool cell_relative = false;
  ClusterPlacement placement = ClusterPlacement::Quadric;
};

/// Clusters `mesh`. Only vertices referenced by a face take part; the output holds one vertex per
/// cluster that is still used by a face, faces in input order, and no two faces on the same three
/// vertices (either orientation: the first one is kept). Deterministic. Throws qem::Error on bad
/// options (no grid and no positive cell, too many cells), an out-of-range index or a non-finite
/// coordinate.
Mesh cluster(MeshView mesh, const ClusterOptions& options);

}  // namespace qem
