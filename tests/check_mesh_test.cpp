// Every library entry point that takes a caller's arrays refuses the same bad meshes with the same
// message, naming the mesh and the first bad element (src/check_mesh.h).
#include "check_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "qem/analyze.h"
#include "qem/cluster.h"
#include "qem/error.h"
#include "qem/io.h"
#include "qem/measure.h"
#include "qem/mesh_info.h"
#include "qem/refit.h"
#include "qem/simplify.h"
#include "test_meshes.h"

namespace {

using qem::Mesh;

struct BadMesh {
  const char* name;
  Mesh mesh;
  const char* message;  // what the error must say after "<what>: "
};

std::vector<BadMesh> bad_meshes() {
  std::vector<BadMesh> out;
  {
    Mesh m = qem::test::cube();
    m.indices[3 * 5 + 1] = 8;  // face 5 names a ninth vertex of eight
    out.push_back({"index out of range", m, "face 5 refers to vertex 8, but there are only 8 vertices"});
  }
  {
    Mesh m = qem::test::cube();
    m.positions[3 * 6 + 2] = std::numeric_limits<double>::quiet_NaN();
    out.push_back({"NaN coordinate", m, "vertex 6 has a non-finite coordinate"});
  }
  {
    Mesh m = qem::test::cube();
    m.positions.insert(m.positions.end(),
                       {std::numeric_limits<double>::infinity(), 0, 0});  // unused vertex 8
    out.push_back({"infinite unused vertex", m, "vertex 8 has a non-finite coordinate"});
  }
  {
    Mesh m = qem::test::cube();
    m.positions.push_back(1);
    out.push_back({"positions not in threes", m, "25 coordinates are not 3 per vertex"});
  }
  {
    Mesh m = qem::test::cube();
    m.indices.pop_back();
    out.push_back({"indices not in threes", m, "35 indices are not 3 per triangle"});
  }
  return out;
}

// Runs `call`, which must throw qem::Error whose message is exactly "<prefix>: <message>".
void expect_refused(const std::function<void()>& call, const std::string& prefix, const BadMesh& bad) {
  try {
    call();
    ADD_FAILURE() << prefix << " accepted a mesh with " << bad.name;
  } catch (const qem::Error& e) {
    EXPECT_EQ(std::string(e.what()), prefix + ": " + bad.message) << bad.name;
  }
}

TEST(CheckMesh, AcceptsAValidMeshAndEmptyOne) {
  EXPECT_NO_THROW(qem::check_mesh(qem::test::icosphere(1), "input"));
  EXPECT_NO_THROW(qem::check_mesh(Mesh{}, "input"));
}

TEST(CheckMesh, EveryEntryPointRefusesTheSameBadMeshesAlike) {
  const Mesh good = qem::test::cube();
  for (const BadMesh& bad : bad_meshes()) {
    const Mesh& m = bad.mesh;
    expect_refused([&] { qem::check_mesh(m, "anything"); }, "anything", bad);
    qem::SimplifyOptions so;
    so.target_faces = 4;
    expect_refused([&] { qem::simplify(m, so); }, "input", bad);
    expect_refused([&] { qem::simplify(Mesh(m), so); }, "input", bad);
    expect_refused([&] { qem::measure(m, good); }, "original", bad);
    expect_refused([&] { qem::measure(good, m); }, "approximation", bad);
    expect_refused(
        [&] {
          Mesh approx = good;
          qem::refit(m, approx);
        },
        "original", bad);
    expect_refused(
        [&] {
          Mesh approx = m;
          qem::refit(good, approx);
        },
        "approximation", bad);
    expect_refused([&] { qem::analyze(m); }, "analyze", bad);
    expect_refused([&] { qem::mesh_info(m); }, "mesh_info", bad);
    qem::ClusterOptions co;
    co.grid[0] = co.grid[1] = co.grid[2] = 2;
    expect_refused([&] { qem::cluster(m, co); }, "cluster", bad);
    for (qem::FileFormat f :
         {qem::FileFormat::Obj, qem::FileFormat::Ply, qem::FileFormat::Stl, qem::FileFormat::Off})
      expect_refused([&] { qem::serialize_mesh(m, f); }, "cannot write mesh", bad);
  }
}

}  // namespace
