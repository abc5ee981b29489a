// SimplifyOptions::vertex_lock: a locked vertex never moves and is never removed, in either order,
// with and without attributes, and through the refit.
#include <gtest/gtest.h>

#include <cmath>

#include "qem/error.h"
#include "qem/simplify.h"
#include "test_meshes.h"

using namespace qem;

namespace {

void expect_locked_kept(const Mesh& in, const std::vector<std::uint8_t>& lock, const SimplifyResult& r) {
  std::size_t checked = 0;
  for (std::uint32_t v = 0; v < in.vertex_count(); ++v) {
    if (!lock[v]) continue;
    const std::uint32_t o = r.output_vertex_of_input[v];
    ASSERT_NE(o, SimplifyResult::kUnmapped) << "locked vertex " << v << " was removed";
    for (int k = 0; k < 3; ++k) EXPECT_EQ(r.mesh.positions[3 * o + k], in.positions[3 * v + k]) << "vertex " << v;
    ++checked;
  }
  EXPECT_GT(checked, 10u);
}

}  // namespace

TEST(VertexLock, LockedVerticesStayInBothOrdersAndWithAttributes) {
  Mesh in = test::icosphere(4);
  std::vector<std::uint8_t> lock(in.vertex_count(), 0);
  for (std::size_t v = 0; v < lock.size(); v += 13) lock[v] = 1;
  for (Scheme scheme : {Scheme::Passes, Scheme::Greedy})
    for (int variant = 0; variant < 3; ++variant) {
      const bool attributes = variant == 1, refit = variant == 2;
      Mesh m = in;
      if (attributes) m.attributes.push_back({"NORMAL", AttributeKind::Normal, 3, m.positions});
      SimplifyOptions o;
      o.scheme = scheme;
      o.target_ratio = 0.05;
      o.map_input_vertices = true;
      o.vertex_lock = lock;
      if (refit) o.refit_rounds = 2;  // the refit holds them too
      const SimplifyResult r = simplify(m, o);
      SCOPED_TRACE(std::string(to_string(scheme)) + " variant " + std::to_string(variant));
      EXPECT_LT(r.mesh.face_count(), in.face_count() / 5);
      expect_locked_kept(in, lock, r);
    }
}

TEST(VertexLock, WrongSizeIsRefused) {
  const Mesh in = test::icosphere(2);
  std::vector<std::uint8_t> lock(3, 1);
  SimplifyOptions o;
  o.target_faces = 10;
  o.vertex_lock = lock;
  EXPECT_THROW(simplify(in, o), Error);
}
