// Malformed input: every case must throw qem::Error whose message names the file and the line
// (text formats) or the element (binary formats) and says what is wrong; never crash or hang.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <regex>
#include <string>
#include <vector>

#include "qem/io.h"
#include "test_meshes.h"

namespace {

using qem::FileFormat;

struct LE {
  std::string s;
  template <class T>
  LE& put(T v) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) std::reverse(b, b + sizeof(T));
    s.append(reinterpret_cast<const char*>(b), sizeof(T));
    return *this;
  }
  LE& text(const std::string& t) {
    s += t;
    return *this;
  }
};

const char* kPlyHead =
    "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

/// Binary PLY with kPlyHead (or `head`), the unit triangle's vertices and then `faces` bytes.
std::string ply_bin(const std::string& faces, const std::string& head = kPlyHead, float y1 = 0.0f) {
  LE b;
  b.text(head).put(0.0f).put(0.0f).put(0.0f).put(1.0f).put(y1).put(0.0f).put(0.0f).put(1.0f).put(0.0f);
  return b.s + faces;
}

std::string face(std::uint8_t n, std::initializer_list<std::int32_t> idx) {
  LE b;
  b.put(n);
  for (std::int32_t i : idx) b.put(i);
  return b.s;
}

std::string stl_bin(std::uint32_t declared, int actual, float bad = 0.0f) {
  LE b;
  b.text(std::string(80, ' ')).put(declared);
  for (int t = 0; t < actual; ++t) {
    for (int k = 0; k < 3; ++k) b.put(0.0f);
    const float c[9] = {0, 0, 0, 1, bad, 0, 0, 1, 0};
    for (float v : c) b.put(v);
    b.put<std::uint16_t>(0);
  }
  return b.s;
}

const char* kAsciiPlyHead =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n";  // body starts on line 10

struct Case {
  const char* label;
  std::string name;  ///< file name given to parse_mesh (its extension picks nothing: format is explicit)
  FileFormat format;
  std::string bytes;
  std::string where;  ///< "line N", "face I", ... ("" when the problem has no location)
  std::string what;   ///< a fragment of the explanation
};

std::vector<Case> cases() {
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const std::string off3 = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n";
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::string garbage;
  std::mt19937 rng(7);
  for (int i = 0; i < 4096; ++i) garbage += static_cast<char>(rng() & 0xFF);
  garbage[0] = '\x01';
  return {
      // --- OBJ ---
      {"obj empty", "e.obj", FileFormat::Obj, "", "", "empty file"},
      {"obj no faces", "nf.obj", FileFormat::Obj, tri, "", "no faces"},
      {"obj index out of range", "r.obj", FileFormat::Obj, tri + "f 1 2 4\n", "line 4", "out of range"},
      {"obj negative out of range", "n.obj", FileFormat::Obj, tri + "f -4 1 2\n", "line 4",
       "before the first"},
      {"obj index zero", "z.obj", FileFormat::Obj, tri + "\nf 0 1 2\n", "line 5", "index 0"},
      {"obj two-vertex face", "two.obj", FileFormat::Obj, tri + "f 1 2\n", "line 4", "at least 3"},
      {"obj nan", "nan.obj", FileFormat::Obj, "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n", "line 2",
       "not finite"},
      {"obj inf", "inf.obj", FileFormat::Obj, "v inf 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "line 1",
       "not finite"},
      {"obj bad number", "bad.obj", FileFormat::Obj, "v 0 abc 0\n", "line 1", "expected a y coordinate"},
      {"obj missing coordinate", "miss.obj", FileFormat::Obj, "v 1 2\nv 0 0 0\n", "line 1",
       "expected a z coordinate"},
      {"obj bad index token", "tok.obj", FileFormat::Obj, tri + "f 1 x 3\n", "line 4", "vertex index"},
      {"obj huge index", "huge.obj", FileFormat::Obj, tri + "f 1 2 99999999999999999999\n", "line 4",
       "vertex index"},
      {"obj binary garbage", "g.obj", FileFormat::Obj, garbage, "", ""},
      // --- PLY ---
      {"ply empty", "e.ply", FileFormat::Ply, "", "", "empty file"},
      {"ply not ply", "np.ply", FileFormat::Ply, "plx\n", "line 1", "not a PLY"},
      {"ply binary garbage", "g.ply", FileFormat::Ply, garbage, "line 1", "not a PLY"},
      {"ply no end_header", "h.ply", FileFormat::Ply, "ply\nformat ascii 1.0\nelement vertex 3\n", "line 4",
       "end_header"},
      {"ply unknown type", "t.ply", FileFormat::Ply,
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float128 x\n", "line 4", "unknown PLY type"},
      {"ply unknown format", "f.ply", FileFormat::Ply, "ply\nformat binary_middle_endian 1.0\n", "line 2",
       "unknown PLY format"},
      // Unknown header keywords are skipped with a warning (io_test.cpp), but a layout line that
      // cannot be read is still an error: skipping it would read the body with the wrong layout.
      {"ply property bad list count type", "lc.ply", FileFormat::Ply,
       "ply\nformat ascii 1.0\nelement face 1\nproperty list float int vertex_indices\n", "line 4",
       "must be an integer type"},
      {"ply property bad list item type", "li.ply", FileFormat::Ply,
       "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar integer vertex_indices\n", "line 4",
       "unknown PLY type 'integer'"},
      {"ply property without name", "pn.ply", FileFormat::Ply,
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float\n", "line 4", "property without a name"},
      {"ply element bad count", "ec.ply", FileFormat::Ply, "ply\nformat ascii 1.0\nelement vertex three\n",
       "line 3", "expected a non-negative element count, found 'three'"},
      {"ply element without count", "en.ply", FileFormat::Ply, "ply\nformat ascii 1.0\nelement vertex\n",
       "line 3", "expected a non-negative element count, found end of line"},
      {"ply element without name", "ew.ply", FileFormat::Ply, "ply\nformat ascii 1.0\nelement\n", "line 3",
       "element without a name"},
      // A word within two letters of a layout keyword is taken for a misspelling and refused:
      // skipped, it would leave the body read with a wrong layout.
      {"ply misspelled element", "me.ply", FileFormat::Ply,
       "ply\nformat ascii 1.0\nelment vertex 3\nproperty float x\n", "line 3", "a misspelled layout keyword?"},
      {"ply misspelled property", "mp.ply", FileFormat::Ply,
       "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
       "propery float z\nend_header\n",
       "line 6", "unknown PLY header keyword 'propery' (a misspelled layout keyword?)"},
      {"ply unknown lines but no end_header", "ue.ply", FileFormat::Ply,
       "ply\nformat ascii 1.0\nCreated by hand\n\x01\x02\x03\n", "line 5", "no end_header"},
      {"ply property before element", "p.ply", FileFormat::Ply, "ply\nformat ascii 1.0\nproperty float x\n",
       "line 3", "before any element"},
      {"ply negative element count", "c.ply", FileFormat::Ply, "ply\nformat ascii 1.0\nelement vertex -3\n",
       "line 3", "non-negative"},
      {"ply no vertex element", "nv.ply", FileFormat::Ply,
       "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n", "",
       "no vertex element"},
      {"ply no faces", "nf.ply", FileFormat::Ply,
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
       "end_header\n0 0 0\n",
       "", "no faces"},
      {"ply truncated vertices", "tv.ply", FileFormat::Ply, std::string(kPlyHead) + std::string(20, '\0'),
       "vertex 0", "too short"},
      {"ply truncated faces", "tf.ply", FileFormat::Ply,
       ply_bin(face(3, {0, 1, 2}) + face(3, {0, 1, 2}).substr(0, 7),
               std::string(kPlyHead).replace(std::string(kPlyHead).find("face 1"), 6, "face 2")),
       "face 1", "truncated"},
      {"ply lies about types", "lie.ply", FileFormat::Ply,
       ply_bin(face(3, {0, 1, 2}),
               "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\n"
               "property double y\nproperty double z\nelement face 1\n"
               "property list uchar int vertex_indices\nend_header\n"),
       "vertex 0", "too short"},
      {"ply index out of range", "r.ply", FileFormat::Ply, ply_bin(face(3, {0, 1, 7})), "face 0",
       "out of range"},
      {"ply negative index", "ni.ply", FileFormat::Ply, ply_bin(face(3, {0, -1, 2})), "face 0", "-1"},
      {"ply two-vertex face", "two.ply", FileFormat::Ply, ply_bin(face(2, {0, 1})), "face 0", "at least 3"},
      {"ply negative list count", "nc.ply", FileFormat::Ply,
       ply_bin(face(0xFD, {0, 1, 2}),
               std::string(kPlyHead).replace(std::string(kPlyHead).find("uchar int"), 9, "char int")),
       "face 0", "-3"},
      {"ply huge list count", "hc.ply", FileFormat::Ply,
       ply_bin(LE().put<std::uint32_t>(4000000000u).put<std::int32_t>(0).s,
               std::string(kPlyHead).replace(std::string(kPlyHead).find("uchar int"), 9, "uint int")),
       "face 0", "exceeds the data"},
      {"ply gigantic vertex count", "gv.ply", FileFormat::Ply,
       "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n" +
           std::string(64, '\0'),
       "vertex 0", "too short"},
      {"ply gigantic extra element", "ge.ply", FileFormat::Ply,
       ply_bin(face(3, {0, 1, 2}),
               std::string(kPlyHead).replace(
                   std::string(kPlyHead).find("end_header"), 10,
                   "element junk 9000000000000000000\nproperty list int int z\nend_header")),
       "junk 0", "too short"},
      {"ply nan binary", "nan.ply", FileFormat::Ply,
       ply_bin(face(3, {0, 1, 2}), kPlyHead, static_cast<float>(nan)), "vertex 1", "not finite"},
      {"ply nan ascii", "nan_a.ply", FileFormat::Ply,
       std::string(kAsciiPlyHead) + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", "line 11", "not finite"},
      {"ply ascii bad number", "bn.ply", FileFormat::Ply,
       std::string(kAsciiPlyHead) + "0 0 0\n1 zz 0\n0 1 0\n3 0 1 2\n", "line 11", "expected a number"},
      {"ply ascii truncated", "at.ply", FileFormat::Ply,
       std::string(kAsciiPlyHead) + "0 0 0\n1 0 0\n0 1 0\n3 0 1", "line 13", "exceeds the data"},
      {"ply ascii out of range", "ar.ply", FileFormat::Ply,
       std::string(kAsciiPlyHead) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "line 13", "out of range"},
      {"ply ascii gigantic count", "ag.ply", FileFormat::Ply,
       "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float "
       "z\n"
       "end_header\n0 0 0\n",
       "line 8", "too short"},
      {"ply more than 2^32 vertices", "a32.ply", FileFormat::Ply,
       "ply\nformat ascii 1.0\nelement vertex 999999999999\nproperty float x\nproperty float y\nproperty "
       "float z\n"
       "end_header\n0 0 0\n",
       "line 3", "too many vertices"},
      {"ply face without index list", "fl.ply", FileFormat::Ply,
       ply_bin(face(3, {0, 1, 2}),
               std::string(kPlyHead).replace(std::string(kPlyHead).find("vertex_indices"), 14, "indices")),
       "face 0", "no vertex_indices"},
      // --- STL ---
      {"stl empty", "e.stl", FileFormat::Stl, "", "", "empty file"},
      {"stl truncated binary", "t.stl", FileFormat::Stl, stl_bin(2, 1), "triangle 1", "declares 2 triangles"},
      {"stl gigantic count", "g.stl", FileFormat::Stl, stl_bin(0xFFFFFFFFu, 1), "triangle 1", "4294967295"},
      {"stl zero triangles", "z.stl", FileFormat::Stl, stl_bin(0, 0), "", "no triangles"},
      {"stl nan binary", "nan.stl", FileFormat::Stl, stl_bin(1, 1, static_cast<float>(nan)), "triangle 0",
       "not finite"},
      {"stl short garbage", "s.stl", FileFormat::Stl, "\x01\x02garbage", "", "too short"},
      {"stl binary garbage", "bg.stl", FileFormat::Stl, garbage, "triangle", "declares"},
      {"stl ascii two-vertex facet", "two.stl", FileFormat::Stl,
       "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid\n",
       "line 6", "at least 3"},
      {"stl ascii unknown token", "u.stl", FileFormat::Stl, "solid x\nfoo\n", "line 2", "unexpected 'foo'"},
      {"stl ascii truncated", "at.stl", FileFormat::Stl,
       "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0", "line 4", "end of file"},
      {"stl ascii nan", "an.stl", FileFormat::Stl,
       "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 inf 0\nvertex 0 1 0\nendloop\n",
       "line 5", "not finite"},
      {"stl ascii no faces", "nf.stl", FileFormat::Stl, "solid x\nendsolid x\n", "", "no faces"},
      // --- OFF ---
      {"off empty", "e.off", FileFormat::Off, "", "", "empty file"},
      {"off bad header", "h.off", FileFormat::Off, "# c\nOFFX\n3 1 0\n", "line 2", "not an OFF"},
      {"off binary", "b.off", FileFormat::Off, "OFF BINARY\n", "line 1", "binary OFF"},
      {"off negative count", "n.off", FileFormat::Off, "OFF\n-1 1 0\n", "line 2", "negative count"},
      {"off gigantic count", "g.off", FileFormat::Off, "OFF\n1000000000 1 0\n0 0 0\n", "line 3", "too short"},
      {"off out of range", "r.off", FileFormat::Off, off3 + "3 0 1 3\n", "line 6", "out of range"},
      {"off negative index", "ni.off", FileFormat::Off, off3 + "3 0 -1 2\n", "line 6", "out of range"},
      {"off two-vertex face", "two.off", FileFormat::Off, off3 + "2 0 1\n", "line 6", "at least 3"},
      {"off huge face count", "hf.off", FileFormat::Off, off3 + "3000000000 0 1 2\n", "line 6",
       "exceeds the data"},
      {"off truncated vertices", "tv.off", FileFormat::Off, "OFF\n3 1 0\n0 0 0\n1 0 0\n", "line 3",
       "too short"},
      {"off truncated last vertex", "tl.off", FileFormat::Off, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1\n\n\n\n\n\n",
       "line 11", "end of file"},
      {"off truncated faces", "tf.off", FileFormat::Off, off3, "line 6", "end of file"},
      {"off nan", "nan.off", FileFormat::Off, "OFF\n3 1 0\n0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n", "line 4",
       "not finite"},
      {"off no faces", "nf.off", FileFormat::Off, "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", "", "no faces"},
      // --- unknown formats ---
      {"auto garbage", "x.bin", FileFormat::Auto, garbage, "", "unknown mesh format"},
      {"auto text", "x.txt", FileFormat::Auto, "hello world\n", "", "unknown mesh format"},
      {"auto empty", "x.dat", FileFormat::Auto, "", "", "empty file"},
  };
}

TEST(IoErrors, EveryMalformedInputThrowsANamedLocatedError) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.label);
    try {
      qem::Mesh m = qem::parse_mesh(c.bytes, c.format, c.name);
      ADD_FAILURE() << c.label << ": no error; read " << m.vertex_count() << " vertices, " << m.face_count()
                    << " faces";
    } catch (const qem::Error& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(c.name, 0), 0u) << msg;  // starts with the file name
      if (!c.where.empty()) {
        EXPECT_NE(msg.find(", " + c.where), std::string::npos) << msg;
      }
      EXPECT_NE(msg.find(c.what), std::string::npos) << msg;
    }
  }
}

TEST(IoErrors, MessagesSayEachWordOnce) {
  auto message = [](const std::string& bytes, FileFormat format, const std::string& name) {
    try {
      qem::parse_mesh(bytes, format, name);
    } catch (const qem::Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // The ASCII PLY body used to say "expected expected a number": the caller's text already began
  // with the "expected" that TextCursor::fail_expected adds.
  EXPECT_EQ(
      message(std::string(kAsciiPlyHead) + "0 0 0\n1 zz 0\n0 1 0\n3 0 1 2\n", FileFormat::Ply, "bn.ply"),
      "bn.ply, line 11: expected a number in vertex 1, found 'zz 0'");
  EXPECT_EQ(message("v 0 abc 0\n", FileFormat::Obj, "bad.obj"),
            "bad.obj, line 1: expected a y coordinate, found 'abc 0'");
  EXPECT_EQ(message("OFFX\n", FileFormat::Off, "h.off"),
            "h.off, line 1: not an OFF file (expected an 'OFF' header)");
  // And no message of the malformed-input table repeats a word ("the the", "a a").
  const std::regex doubled(R"(\b([A-Za-z]+) \1\b)");
  for (const Case& c : cases()) {
    const std::string msg = message(c.bytes, c.format, c.name);
    EXPECT_FALSE(std::regex_search(msg, doubled)) << c.label << ": " << msg;
  }
}

TEST(IoErrors, LoadMeshNamesMissingUnreadableAndUnknownFiles) {
  const std::string dir = qem::test::temp_dir() + "/errors";
  std::filesystem::create_directories(dir);
  auto expect_error = [](const std::string& path, const std::string& what) {
    try {
      qem::load_mesh(path);
      ADD_FAILURE() << path << ": no error";
    } catch (const qem::Error& e) {
      std::string msg = e.what();
      EXPECT_NE(msg.find(path), std::string::npos) << msg;
      EXPECT_NE(msg.find(what), std::string::npos) << msg;
    }
  };
  expect_error(dir + "/missing.obj", "cannot open");
  expect_error(dir, "is a directory");
  {
    std::ofstream(dir + "/mesh.xyz") << "this is not a mesh\n";
    std::ofstream(dir + "/empty.ply");
  }
  expect_error(dir + "/mesh.xyz", "extension '.xyz'");
  expect_error(dir + "/empty.ply", "empty file");
  // The input is never modified, even when it is malformed.
  const std::string bad = dir + "/bad.off";
  std::ofstream(bad) << "OFF\n3 1 0\n0 0 0\n";
  auto before = std::filesystem::last_write_time(bad);
  expect_error(bad, "too short");
  EXPECT_EQ(std::filesystem::last_write_time(bad), before);
  EXPECT_EQ(std::filesystem::file_size(bad), 16u);
}

/// Every prefix and many byte-flipped copies of a valid file: each parse either throws qem::Error
/// or yields a mesh with finite coordinates and in-range indices.
void mutate_and_parse(const std::string& valid, FileFormat format, const char* name) {
  auto check = [&](const std::string& bytes) {
    try {
      qem::Mesh m = qem::parse_mesh(bytes, format, name);
      ASSERT_GT(m.face_count(), 0u);
      for (double c : m.positions) ASSERT_TRUE(std::isfinite(c));
      for (std::uint32_t i : m.indices) ASSERT_LT(i, m.vertex_count());
    } catch (const qem::Error& e) {
      ASSERT_EQ(std::string(e.what()).rfind(name, 0), 0u) << e.what();
    }
  };
  for (std::size_t n = 0; n < valid.size(); n += 1 + valid.size() / 300) check(valid.substr(0, n));
  std::mt19937 rng(12345);
  for (int trial = 0; trial < 300; ++trial) {
    std::string b = valid;
    int flips = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < flips; ++k) b[rng() % b.size()] = static_cast<char>(rng() & 0xFF);
    check(b);
  }
}

TEST(IoErrors, MutatedFilesNeverCrash) {
  qem::Mesh m = qem::test::icosphere(1);
  m.vertex_properties.push_back({"w", std::vector<double>(m.vertex_count(), 1.5)});
  for (bool binary : {true, false}) {
    mutate_and_parse(qem::serialize_mesh(m, FileFormat::Ply, binary), FileFormat::Ply, "m.ply");
    mutate_and_parse(qem::serialize_mesh(m, FileFormat::Stl, binary), FileFormat::Stl, "m.stl");
  }
  mutate_and_parse(qem::serialize_mesh(m, FileFormat::Obj), FileFormat::Obj, "m.obj");
  mutate_and_parse(qem::serialize_mesh(m, FileFormat::Off), FileFormat::Off, "m.off");
  mutate_and_parse(qem::serialize_mesh(m, FileFormat::Off), FileFormat::Auto, "m.any");
}

}  // namespace
