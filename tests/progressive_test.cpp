// Progressive records (GH97 §3): one run, every intermediate mesh. The central property: replaying
// a prefix of a record gives exactly (bit for bit) the mesh `simplify` returns for that target.
#include "qem/progressive.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "qem/io.h"
#include "qem/simplify.h"
#include "test_meshes.h"
#include "view/lod_manifest.h"

namespace qem {
namespace {

double waves(double x, double y) { return 0.15 * std::sin(7 * x) * std::cos(5 * y) + 0.05 * x * y; }

// An icosphere with the input quirks the record must renumber around: an unreferenced vertex, a
// degenerate face and a duplicate face (neither is among the run's initial faces).
Mesh quirky_sphere() {
  Mesh m = test::icosphere(3);
  m.positions.insert(m.positions.begin(), {5, 5, 5});  // vertex 0: unreferenced
  for (std::uint32_t& i : m.indices) ++i;
  m.indices.insert(m.indices.begin() + 30, {3, 3, 7});                            // degenerate
  m.indices.insert(m.indices.end(), {m.indices[3], m.indices[4], m.indices[5]});  // duplicate of face 1
  return m;
}

struct Case {
  const char* name;
  std::function<Mesh()> mesh;
  std::function<void(SimplifyOptions&)> options;
};

std::vector<Case> cases() {
  return {
      {"sphere_default", [] { return test::icosphere(4); }, [](SimplifyOptions&) {}},
      {"quirky_input", quirky_sphere, [](SimplifyOptions&) {}},
      {"height_field_boundary", [] { return test::height_field(24, waves); }, [](SimplifyOptions&) {}},
      {"grid_lock_border", [] { return test::height_field(20, waves); },
       [](SimplifyOptions& o) { o.lock_border = true; }},
      {"uniform_endpoints", [] { return test::icosphere(3); },
       [](SimplifyOptions& o) {
         o.weighting = Weighting::Uniform;
         o.placement = Placement::Endpoints;
       }},
      {"threshold_virtual_pairs",
       [] {
         return test::concatenated(test::icosphere(2), test::transformed(test::icosphere(2), 1, 2.05, 0, 0));
       },
       [](SimplifyOptions& o) { o.threshold = 0.3; }},
      {"penalize_no_topology", [] { return test::height_field(16, waves); },
       [](SimplifyOptions& o) {
         o.inversion = InversionPolicy::Penalize;
         o.preserve_topology = false;
         o.placement = Placement::Midpoint;
       }},
  };
}

SimplifyResult simplify_to(const Mesh& m, const std::function<void(SimplifyOptions&)>& set, std::size_t faces,
                           ContractionLog* log = nullptr) {
  SimplifyOptions o;
  set(o);
  o.target_faces = faces;
  ContractionRecorder recorder;
  SimplifyResult r = simplify(m, o, log ? &recorder : nullptr);
  if (log) *log = std::move(recorder.log);
  return r;
}

// --- replay == simplify ----------------------------------------------------------------------

TEST(Progressive, ReplayEqualsDirectSimplify) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    const Mesh m = c.mesh();
    ContractionLog log;
    const std::size_t smallest = 8;
    const SimplifyResult full = simplify_to(m, c.options, smallest, &log);
    const Record rec = make_record(m, log);
    EXPECT_EQ(rec.size(), full.contractions);
    EXPECT_EQ(rec.final_faces(), full.mesh.face_count());
    const std::size_t nf = rec.base.face_count();
    EXPECT_EQ(nf, full.input_faces);
    // Any order: replay_levels sorts internally and answers in the order asked.
    std::vector<std::size_t> targets = {nf / 4, nf + 10,     smallest, nf,     37,
                                        nf - 1, nf * 9 / 10, nf / 2,   nf / 10};
    const std::vector<ReplayLevel> levels = replay_levels(rec, targets);
    for (std::size_t i = 0; i < targets.size(); ++i) {
      SCOPED_TRACE("target " + std::to_string(targets[i]));
      const SimplifyResult direct = simplify_to(m, c.options, targets[i]);
      const Mesh one = replay(rec, targets[i]);
      EXPECT_EQ(one.indices, direct.mesh.indices);
      EXPECT_EQ(one.positions, direct.mesh.positions);  // exact: same doubles
      EXPECT_EQ(levels[i].mesh.indices, direct.mesh.indices);
      EXPECT_EQ(levels[i].mesh.positions, direct.mesh.positions);
      EXPECT_EQ(levels[i].contractions, direct.contractions);
      EXPECT_EQ(levels[i].max_error, direct.max_error);
    }
  }
}

// Asking below what the run reached gives the run's final mesh, not an error.
TEST(Progressive, ReplayBelowTheRecordGivesTheFinalMesh) {
  const Mesh m = test::icosphere(3);
  ContractionLog log;
  const SimplifyResult r = simplify_to(
      m, [](SimplifyOptions&) {}, 200, &log);
  const Record rec = make_record(m, log);
  const Mesh all = replay(rec, 0);
  EXPECT_EQ(all.indices, r.mesh.indices);
  EXPECT_EQ(all.positions, r.mesh.positions);
}

// A real scanned mesh, when the shared data is present.
TEST(Progressive, ReplayEqualsDirectSimplifyOnBunny) {
  const std::string path = test::shared_data("gh_bunny_zipper.ply");
  if (path.empty()) GTEST_SKIP() << "shared data not available";
  const Mesh m = load_mesh(path);
  ContractionLog log;
  simplify_to(
      m, [](SimplifyOptions&) {}, 300, &log);
  const Record rec = make_record(m, log);
  for (std::size_t target : {std::size_t(50000), std::size_t(7000), std::size_t(300)}) {
    const SimplifyResult direct = simplify_to(
        m, [](SimplifyOptions&) {}, target);
    const Mesh replayed = replay(rec, target);
    EXPECT_EQ(replayed.indices, direct.mesh.indices) << target;
    EXPECT_EQ(replayed.positions, direct.mesh.positions) << target;
  }
}

// --- the file format -------------------------------------------------------------------------

Record sample_record() {
  const Mesh m = quirky_sphere();
  ContractionLog log;
  simplify_to(
      m, [](SimplifyOptions&) {}, 40, &log);
  return make_record(m, log);
}

void expect_same(const Record& a, const Record& b) {
  EXPECT_EQ(a.base.positions, b.base.positions);
  EXPECT_EQ(a.base.indices, b.base.indices);
  EXPECT_EQ(a.kept, b.kept);
  EXPECT_EQ(a.removed, b.removed);
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.error, b.error);
  EXPECT_EQ(a.dead_begin, b.dead_begin);
  EXPECT_EQ(a.dead_faces, b.dead_faces);
}

TEST(Progressive, RecordRoundTrip) {
  const Record rec = sample_record();
  ASSERT_GT(rec.size(), 100u);
  const std::string bytes = serialize_record(rec);
  EXPECT_EQ(bytes.size(), 48 + 24 * rec.base.vertex_count() + 12 * rec.base.face_count() + 44 * rec.size() +
                              4 * rec.dead_faces.size());
  expect_same(parse_record(bytes, "mem"), rec);

  const std::string path = test::temp_dir() + "/prog_roundtrip.qrec";
  write_record(path, rec);
  const Record back = read_record(path);
  expect_same(back, rec);
  EXPECT_EQ(serialize_record(back), bytes);
  // The quirks were dropped: the base holds only the used vertices and the initial faces.
  const Mesh input = quirky_sphere();
  EXPECT_EQ(rec.base.vertex_count(), input.vertex_count() - 1);
  EXPECT_EQ(rec.base.face_count(), input.face_count() - 2);
}

TEST(Progressive, RecordIsLittleEndianWithMagicAndVersion) {
  const std::string bytes = serialize_record(sample_record());
  EXPECT_EQ(bytes.substr(0, 8), std::string("QEMREC\x1a\n", 8));
  EXPECT_EQ(bytes.substr(8, 8), std::string("\x01\0\0\0\0\0\0\0", 8));  // version 1, flags 0
  Record r = sample_record();
  r.double_input = true;
  const std::string flagged = serialize_record(r);
  EXPECT_EQ(flagged.substr(12, 4), std::string("\x01\0\0\0", 4));
  EXPECT_TRUE(parse_record(flagged, "flagged").double_input);
  EXPECT_FALSE(parse_record(bytes, "plain").double_input);
}

TEST(Progressive, MakeRecordRejectsAForeignLog) {
  const Mesh m = test::icosphere(2);
  ContractionLog log;
  simplify_to(
      m, [](SimplifyOptions&) {}, 20, &log);
  EXPECT_THROW(make_record(test::tetrahedron(), log), Error);
}

// Offsets in the sample file (docs/record-format.md).
struct Layout {
  std::size_t nv, nf, vertices = 48, faces, contractions;
  explicit Layout(const Record& r)
      : nv(r.base.vertex_count()),
        nf(r.base.face_count()),
        faces(48 + 24 * nv),
        contractions(faces + 12 * nf) {}
  // Offset of contraction i (walking the variable-length entries).
  std::size_t contraction(const Record& r, std::size_t i) const {
    return contractions + 44 * i + 4 * std::size_t(r.dead_begin[i]);
  }
};

void put_u32(std::string& s, std::size_t at, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) s[at + k] = char((v >> (8 * k)) & 0xff);
}
void put_u64(std::string& s, std::size_t at, std::uint64_t v) {
  for (int k = 0; k < 8; ++k) s[at + k] = char((v >> (8 * k)) & 0xff);
}
void put_f64(std::string& s, std::size_t at, double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, 8);
  put_u64(s, at, bits);
}
std::uint32_t get_u32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  for (int k = 0; k < 4; ++k) v |= std::uint32_t(std::uint8_t(s[at + k])) << (8 * k);
  return v;
}

TEST(Progressive, ReaderRejectsCorruptFiles) {
  const Record rec = sample_record();
  const Layout L(rec);
  const std::string good = serialize_record(rec);
  ASSERT_GE(rec.dead_begin[1], 1u);
  ASSERT_GE(rec.dead_begin[2] - rec.dead_begin[1], 1u);
  const std::size_t c0 = L.contraction(rec, 0), c1 = L.contraction(rec, 1);
  struct Corrupt {
    const char* name;
    std::function<void(std::string&)> edit;
    const char* message;
  };
  const std::vector<Corrupt> table = {
      {"empty", [](std::string& s) { s.clear(); }, "truncated header"},
      {"half header", [](std::string& s) { s.resize(20); }, "truncated header"},
      {"bad magic", [](std::string& s) { s[0] = 'X'; }, "bad magic"},
      {"future version", [](std::string& s) { put_u32(s, 8, 2); }, "unsupported record version 2"},
      {"unknown flags", [](std::string& s) { put_u32(s, 12, 2); }, "unknown flags 2"},
      {"unknown flags beside a known one", [](std::string& s) { put_u32(s, 12, 0x80000001u); },
       "unknown flags"},
      {"vertex count beyond 32 bits", [](std::string& s) { put_u64(s, 16, std::uint64_t(1) << 40); },
       "32-bit"},
      // Announces 4 billion vertices on a small file: rejected by size, before any allocation.
      {"lying vertex count", [](std::string& s) { put_u64(s, 16, 0xffffffffu); }, "truncated"},
      {"lying face count", [](std::string& s) { put_u64(s, 24, 0xfffffff0u); }, "truncated"},
      {"more contractions than vertices", [&](std::string& s) { put_u64(s, 32, L.nv + 1); },
       "more contractions"},
      {"more dead faces than faces", [&](std::string& s) { put_u64(s, 40, L.nf + 1); }, "more dead faces"},
      {"truncated by one byte", [](std::string& s) { s.pop_back(); }, "truncated"},
      {"truncated mid vertices", [&](std::string& s) { s.resize(L.vertices + 30); }, "truncated"},
      {"trailing byte", [](std::string& s) { s.push_back('\0'); }, "unexpected bytes"},
      {"nan coordinate", [&](std::string& s) { put_f64(s, L.vertices + 8, std::nan("")); },
       "vertex 0: non-finite"},
      {"corner out of range", [&](std::string& s) { put_u32(s, L.faces + 12 + 4, std::uint32_t(L.nv)); },
       "face 1: refers to vertex"},
      {"degenerate face", [&](std::string& s) { put_u32(s, L.faces + 4, get_u32(s, L.faces)); },
       "face 0: degenerate"},
      {"kept out of range", [&](std::string& s) { put_u32(s, c0, std::uint32_t(L.nv + 7)); },
       "contraction 0: vertex id out of range"},
      {"kept == removed", [&](std::string& s) { put_u32(s, c0, get_u32(s, c0 + 4)); },
       "contraction 0: keeps and removes the same vertex"},
      {"vertex removed twice", [&](std::string& s) { put_u32(s, c1 + 4, get_u32(s, c0 + 4)); },
       "contraction 1: uses a vertex removed"},
      {"infinite position", [&](std::string& s) { put_f64(s, c0 + 16, INFINITY); },
       "contraction 0: non-finite position"},
      {"negative error", [&](std::string& s) { put_f64(s, c0 + 32, -1.0); }, "contraction 0: error"},
      {"dead face out of range", [&](std::string& s) { put_u32(s, c0 + 44, std::uint32_t(L.nf)); },
       "contraction 0: dead face"},
      {"face dies twice", [&](std::string& s) { put_u32(s, c1 + 44, get_u32(s, c0 + 44)); },
       "contraction 1: face"},
      {"dead count too large", [&](std::string& s) { put_u32(s, c0 + 40, get_u32(s, c0 + 40) + 1000000); },
       "dead face count"},
  };
  for (const Corrupt& c : table) {
    SCOPED_TRACE(c.name);
    std::string bytes = good;
    c.edit(bytes);
    try {
      parse_record(bytes, "bad.qrec");
      ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("bad.qrec", 0), 0u) << what;  // names the file first
      EXPECT_NE(what.find(c.message), std::string::npos) << what;
    }
  }
  // Every truncation point fails cleanly (no crash, no acceptance).
  for (std::size_t len = 0; len < good.size(); len += 97)
    EXPECT_THROW(parse_record(std::string_view(good).substr(0, len), "cut.qrec"), Error) << len;
  EXPECT_THROW(read_record(test::temp_dir() + "/prog_missing.qrec"), Error);
}

TEST(Progressive, Deterministic) {
  EXPECT_EQ(serialize_record(sample_record()), serialize_record(sample_record()));
}

// --- the CLI ---------------------------------------------------------------------------------

using test::slurp;
int run(const std::string& args) { return test::run_qem_quietly(args); }

TEST(Progressive, CliReplayIsByteIdenticalToSimplify) {
  const std::string dir = test::temp_dir() + "/prog_cli_replay";
  std::filesystem::create_directories(dir);
  const std::string in = dir + "/in.ply";
  save_mesh(in, test::concatenated(test::icosphere(4),
                                   test::transformed(test::height_field(20, waves), 1, 2, 0, 0)));
  const std::string opts = " --weighting angle --placement segment --boundary-weight 2";
  ASSERT_EQ(run("simplify " + in + " " + dir + "/final.ply --faces 60 --record " + dir + "/run.qrec" + opts),
            0);
  ASSERT_EQ(
      run("simplify " + in + " " + dir + "/final2.ply --faces 60 --record " + dir + "/run2.qrec" + opts), 0);
  EXPECT_EQ(slurp(dir + "/run.qrec"), slurp(dir + "/run2.qrec"));  // deterministic
  for (int n : {5000, 4999, 2222, 1001, 800, 61, 60}) {
    SCOPED_TRACE(n);
    const std::string s = dir + "/s" + std::to_string(n) + ".ply",
                      r = dir + "/r" + std::to_string(n) + ".ply";
    ASSERT_EQ(run("simplify " + in + " " + s + " --faces " + std::to_string(n) + opts), 0);
    ASSERT_EQ(run("replay " + dir + "/run.qrec " + r + " --faces " + std::to_string(n)), 0);
    const std::string a = slurp(s), b = slurp(r);
    EXPECT_FALSE(a.empty());
    EXPECT_TRUE(a == b) << "files differ";
  }
  // A broken record is a one-line error, not a crash.
  { std::ofstream(dir + "/broken.qrec", std::ios::binary) << slurp(dir + "/run.qrec").substr(0, 100); }
  EXPECT_NE(run("replay " + dir + "/broken.qrec " + dir + "/x.ply 2>/dev/null"), 0);
}

TEST(Progressive, CliDoublePlyStaysDoubleInSimplifyLodAndReplay) {
  // A PLY storing doubles is written back with doubles by simplify and lod, and by replay (the
  // record's header says the input stored doubles) without being asked.
  const std::string dir = test::temp_dir() + "/prog_cli_double";
  std::filesystem::create_directories(dir);
  const std::string in = dir + "/in.ply";
  SaveOptions o;
  o.double_precision = true;
  save_mesh(in, test::transformed(test::icosphere(3), 1, 4.5e6, -3.2e5, 1e3), o);
  ASSERT_EQ(run("simplify " + in + " " + dir + "/s.ply --ratio 0.25 --record " + dir + "/run.qrec"), 0);
  ASSERT_EQ(run("lod " + in + " " + dir + "/lod --ratios 0.25 --no-refit"), 0);  // as --record
  ASSERT_EQ(run("replay " + dir + "/run.qrec " + dir + "/r.ply"), 0);
  const std::string s = slurp(dir + "/s.ply");
  EXPECT_NE(s.find("property double x"), std::string::npos);
  EXPECT_TRUE(s == slurp(dir + "/lod/in_lod0.ply")) << "lod level differs from simplify";
  EXPECT_TRUE(s == slurp(dir + "/r.ply")) << "replay differs from simplify";
  EXPECT_TRUE(read_record(dir + "/run.qrec").double_input);
}

TEST(Progressive, CliFaceColoursSurviveSimplifyAndLodAndRefuseARecord) {
  // A PLY with face colours and no vertex attributes (Hoppe's cessna is such a file): its colours
  // are materials, which the output keeps, in simplify and in each lod level; a record, which holds
  // positions and faces only, is refused rather than replayed without them.
  const std::string dir = test::temp_dir() + "/prog_cli_face_colours";
  std::filesystem::create_directories(dir);
  Mesh m = test::icosphere(4);
  m.material_names = {"rgb(255,0,0)", "rgb(0,0,255)"};
  for (std::size_t f = 0; f < m.face_count(); ++f) {
    double x = 0;
    for (int k = 0; k < 3; ++k) x += m.positions[3 * m.indices[3 * f + k]];
    m.face_materials.push_back(x < 0 ? 0 : 1);
  }
  const std::string in = dir + "/coloured.ply";
  save_mesh(in, m);
  const auto check = [](const Mesh& out) {
    EXPECT_EQ(out.material_names, (std::vector<std::string>{"rgb(255,0,0)", "rgb(0,0,255)"}));
    ASSERT_EQ(out.face_materials.size(), out.face_count());
    std::size_t red = 0;
    for (std::uint32_t k : out.face_materials) red += k == 0;
    EXPECT_GT(red, 0u);
    EXPECT_LT(red, out.face_count());
  };
  ASSERT_EQ(run("simplify " + in + " " + dir + "/out.ply --ratio 0.1"), 0);
  check(load_mesh(dir + "/out.ply"));
  ASSERT_EQ(run("lod " + in + " " + dir + "/lod --ratios 0.5,0.1"), 0);
  for (const view::ManifestLevel& level : view::read_lod_manifest(dir + "/lod/manifest.json"))
    check(load_mesh(level.path));
  EXPECT_NE(
      run("simplify " + in + " " + dir + "/rec.ply --ratio 0.1 --record " + dir + "/run.qrec 2>/dev/null"),
      0);
}

TEST(Progressive, CliLodWritesLevelsAndManifest) {
  const std::string dir = test::temp_dir() + "/prog_cli_lod";
  std::filesystem::create_directories(dir);
  const std::string in = dir + "/shape.obj";
  save_mesh(in, test::icosphere(4));  // 5120 faces
  ASSERT_EQ(run("lod " + in + " " + dir + "/out --ratios 0.5,0.1,0.02 --format off --placement endpoints"),
            0);
  const std::vector<view::ManifestLevel> levels = view::read_lod_manifest(dir + "/out/manifest.json");
  ASSERT_EQ(levels.size(), 3u);
  const double ratios[] = {0.5, 0.1, 0.02};
  double previous_error = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(std::filesystem::path(levels[i].path).filename().string(),
              "shape_lod" + std::to_string(i) + ".off");
    const std::string direct = dir + "/direct" + std::to_string(i) + ".off";
    ASSERT_EQ(run("simplify " + in + " " + direct + " --ratio " + std::to_string(ratios[i]) +
                  " --placement endpoints"),
              0);
    EXPECT_TRUE(slurp(direct) == slurp(levels[i].path)) << "level differs from a direct simplify";
    const Mesh level = load_mesh(levels[i].path);
    EXPECT_EQ(levels[i].faces, level.face_count());
    EXPECT_EQ(levels[i].vertices, level.vertex_count());
    EXPECT_LE(level.face_count(), std::size_t(std::floor(ratios[i] * 5120)));
    EXPECT_GE(levels[i].error, previous_error);  // max error so far never decreases
    previous_error = levels[i].error;
  }
  EXPECT_GT(previous_error, 0);
  // Same input, same options: same bytes.
  ASSERT_EQ(run("lod " + in + " " + dir + "/again --ratios 0.5,0.1,0.02 --format off --placement endpoints"),
            0);
  EXPECT_TRUE(slurp(dir + "/out/manifest.json") == slurp(dir + "/again/manifest.json"));
  EXPECT_TRUE(slurp(dir + "/out/shape_lod2.off") == slurp(dir + "/again/shape_lod2.off"));
  EXPECT_NE(run("lod " + in + " " + dir + "/bad --ratios 0.5 --faces 100 2>/dev/null"), 0);
  EXPECT_NE(run("lod " + in + " " + dir + "/bad --ratios 1.5 2>/dev/null"), 0);
}

}  // namespace
}  // namespace qem
