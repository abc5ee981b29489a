// glTF 2.0 (.gltf with embedded or external buffers, and .glb) read and written with pass-through:
// a GltfDocument gives each triangle primitive as a qem::Mesh, takes new geometry for any of them,
// and writes the file back with everything else as it was (materials, textures, image bytes,
// samplers, nodes, skins, animations, cameras, extras, extensions, unknown ones included).
//
// The simplest use, simplifying every primitive that can be:
//
//   qem::GltfDocument doc = qem::GltfDocument::load("in.glb");
//   for (std::size_t i = 0; i < doc.primitives().size(); ++i)
//     if (doc.primitives()[i].simplifiable) doc.replace(i, my_simplify(doc.mesh(i)));
//   doc.save("out.glb");
//
// simplify_document (qem/gltf_simplify.h) does this with qem's simplifier and one error budget
// shared by the scene in world units. load_mesh (qem/io.h) on a .gltf/.glb gives the whole scene
// merged into one Mesh instead.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "qem/error.h"
#include "qem/mesh.h"

namespace qem {

/// One primitive of the document (glTF `meshes[mesh].primitives[primitive]`).
struct GltfPrimitiveInfo {
  std::size_t mesh = 0;       ///< index in the document's `meshes`
  std::size_t primitive = 0;  ///< index in that mesh's `primitives`
  int material = -1;          ///< glTF material index, -1 when none (the default material)
  int mode = 4;               ///< glTF primitive mode; 4 = TRIANGLES, the only one read as a Mesh
  std::size_t vertex_count = 0;
  std::size_t face_count = 0;           ///< triangles (0 when mode is not TRIANGLES)
  std::vector<std::string> attributes;  ///< the glTF semantics present, POSITION first
  std::size_t morph_targets = 0;        ///< number of morph targets
  /// True when `mesh()` and `replace()` may be used: mode TRIANGLES with a POSITION.
  bool simplifiable = false;
  std::string why_not;  ///< why it is not simplifiable ("" when it is)
  /// The largest factor by which the default scene's nodes that place this primitive's mesh scale
  /// a length (the largest singular value of their world matrix; with a skin, of each joint's
  /// world matrix times its inverse bind matrix, the bind pose that glTF 2.0 §3.7.3 draws
  /// instead of the node's transform). 1 when no node places the mesh. A mesh that several nodes
  /// instance (or one node by EXT_mesh_gpu_instancing) takes the largest: its errors are measured
  /// where they are seen the biggest.
  double world_scale = 1;
  /// The spacing of the grid on which a Draco-compressed primitive's positions were quantized, in
  /// the mesh's units (range / (2^bits - 1)); 0 when they were stored as they are. Draco quantizes
  /// each primitive in its own box, so where two primitives of one mesh meet, their positions
  /// differ by up to half of each one's spacing: simplify_document joins them within that.
  double position_step = 0;
  /// Primitives whose meshes the default scene draws by exactly the same world matrices (not
  /// skinned) share this number, the lowest such mesh index: an exporter that splits one object
  /// into a mesh per material puts each under its own node, and their primitives meet where their
  /// positions are equal. Otherwise it is `mesh`.
  std::size_t placement = 0;
};

/// A loaded glTF file. Movable, not copyable.
class GltfDocument {
 public:
  GltfDocument();
  ~GltfDocument();
  GltfDocument(GltfDocument&&) noexcept;
  GltfDocument& operator=(GltfDocument&&) noexcept;

  /// Reads a .gltf (buffers embedded as data: URIs or in files beside it) or a .glb (by content,
  /// whatever the extension). Images are kept as bytes, never decoded; external image files are
  /// referenced by their URI, not read. Throws qem::Error naming the file (and the mesh, primitive
  /// and accessor when one is at fault) on malformed input, on accessors that lie outside their
  /// buffer, indices beyond the vertex count, or non-finite values. Geometry compressed with
  /// KHR_draco_mesh_compression or EXT_meshopt_compression is decoded here (a malformed stream
  /// throws); KHR_meshopt_compression is refused by name.
  static GltfDocument load(const std::string& path);
  /// Same, from bytes in memory; `name` is used in messages. Buffers must be embedded (.glb or
  /// data: URIs): no file is read.
  static GltfDocument parse(std::string_view bytes, const std::string& name);

  /// Every primitive of every mesh, in document order.
  const std::vector<GltfPrimitiveInfo>& primitives() const;

  /// Primitive `i` as a Mesh: positions from POSITION, indices (0..n-1 when not indexed), and
  /// the attributes NORMAL -> Normal, TEXCOORD_n -> TexCoord, COLOR_n -> Color (normalised
  /// integers decoded to [0, 1]), JOINTS_0 -> JointIndices, WEIGHTS_0 -> JointWeights,
  /// TANGENT -> Tangent, anything else -> Scalar, each named by its semantic; morph target k's
  /// offsets as Scalar attributes named "target<k>/<SEMANTIC>" (POSITION, NORMAL; a TANGENT
  /// offset is dropped with the TANGENT), which `replace` writes back into the targets. Quantized
  /// (KHR_mesh_quantization) and sparse accessors are decoded. The node transform is not applied.
  /// Throws when the primitive is not simplifiable (see GltfPrimitiveInfo).
  Mesh mesh(std::size_t i) const;

  /// Replaces the geometry of primitive `i` (written by the next save). `mesh` must carry the same
  /// attributes as mesh(i) (names and component counts), except TANGENT, which is dropped on
  /// replaced primitives whatever the mesh holds: tangents follow the UV parametrisation, which
  /// simplification changes, and renderers compute MikkTSpace tangents when they are absent.
  /// Face materials are ignored (the primitive keeps its material). Throws qem::Error when the
  /// primitive is not simplifiable or the mesh does not match.
  void replace(std::size_t i, Mesh mesh);

  /// Writes the document atomically: .glb (binary) or .gltf (JSON, buffers embedded as base64)
  /// by the extension of `path`. Replaced primitives get new accessors and buffer views; the data
  /// only they used is dropped and the binary buffer is re-packed; everything else is unchanged.
  void save(const std::string& path) const;
  /// The bytes save() would write; `binary` chooses .glb or .gltf.
  std::string serialize(bool binary) const;

  /// The whole default scene (or every root node when there is none) merged into one Mesh, in
  /// world space (node transforms applied; normals with the inverse transpose), with
  /// face_materials = the glTF material of each face and material_names the glTF material names
  /// (a face with no material gets the extra name "(default)" after them), and the attributes
  /// that every merged primitive carries. What load_mesh returns for glTF. A skinned mesh is
  /// placed in its bind pose (its joints' matrices blended by its weights; each face wound by the
  /// sign of their mean's determinant); a node with EXT_mesh_gpu_instancing draws its mesh once
  /// per instance (the node's matrix times the instance's); morph targets are not applied (the
  /// rest shape) and their offsets are not merged.
  Mesh scene_mesh() const;

  /// What was read leniently or will be written differently (TANGENT dropped on a replaced
  /// primitive, primitives left untouched because their mode is not TRIANGLES...), one sentence each.
  std::vector<std::string> notes() const;

 private:
  static GltfDocument from_bytes(std::string_view bytes, const std::string& name, const std::string& base_dir,
                                 bool read_files);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Serialises a single Mesh as a minimal glTF: one mesh with one primitive per material (all
/// sharing the vertex accessors), one node, one scene, and one plain material per material name.
std::string serialize_gltf(const Mesh& mesh, bool binary);

}  // namespace qem
