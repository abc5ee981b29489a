// Inputs the fuzzers found (and hand-made nasty ones in the same spirit), replayed through exactly
// the checks the fuzzers make (fuzz/fuzz_checks.h). A new finding becomes one more row here: its
// bytes, the format, and what the library must do with it.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "../fuzz/fuzz_checks.h"
#include "qem/error.h"
#include "qem/io.h"
#include "qem/simplify.h"

namespace qem {
namespace {

enum class Expect {
  Reject,  ///< the reader must throw qem::Error
  Either,  ///< qem::Error or a valid mesh, as long as nothing else happens
};

struct ParserCase {
  const char* name;
  FileFormat format;
  std::string bytes;
  Expect expect;
};

/// The bytes of a hex string (how fuzzer findings are embedded).
std::string from_hex(std::string_view hex) {
  auto nibble = [](char c) { return c <= '9' ? c - '0' : c - 'a' + 10; };
  std::string s;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2) s += char(nibble(hex[i]) * 16 + nibble(hex[i + 1]));
  return s;
}

/// Little-endian 32-bit value as 4 bytes.
std::string le32(std::uint32_t v) {
  std::string s;
  for (int k = 0; k < 4; ++k) s += char((v >> (8 * k)) & 0xff);
  return s;
}

std::string le_float(float x) {
  std::uint32_t bits;
  std::memcpy(&bits, &x, 4);
  return le32(bits);
}

/// Binary STL: 80-byte header, the triangle count as stored, then the given facets.
std::string binary_stl(std::uint32_t claimed, const std::vector<std::array<float, 9>>& facets) {
  std::string s(80, ' ');
  s += le32(claimed);
  for (const auto& f : facets) {
    for (int k = 0; k < 3; ++k) s += le_float(0);
    for (float x : f) s += le_float(x);
    s += std::string(2, '\0');
  }
  return s;
}

std::string ply_header(const std::string& format, const std::string& body) {
  return "ply\nformat " + format + " 1.0\n" + body + "end_header\n";
}

const std::string kTriangleVerts = "0 0 0\n1 0 0\n0 1 0\n";

std::vector<ParserCase> parser_cases() {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::string ply_xyz = "property float x\nproperty float y\nproperty float z\n";
  return {
      // --- found by fuzz_ply (scripts/fuzz.sh, first run): the reader accepted the header token
      // "q\0\0a" (NUL bytes) as a property name, which the PLY writer then refuses. Refusing with
      // qem::Error is fine; nothing may crash, and what is written must read back.
      {"ply_property_name_with_nul_bytes", FileFormat::Ply,
       from_hex(
           "706c790a666f726d61742062696e6172795f6c6974746c655f656e6469616e20312e300a636f6d6d656e742077726974"
           "74656e2062792071656d0a656c656d656e74207665727465782031360a70726f706572747920666c6f617420780a7072"
           "6f706572747920666c6f617420790a70726f706572747920666c6f6174207a0a70726f706572747920666c6f61742071"
           "000061200001a91a75616c6974790a656c656d656e7420666163652031380a70726f7065727479206c69737420756368"
           "617220696e74207665727465785f696e64696365730a656e645f6865616465720a000000000000400000000000000000"
           "00abaaaa3e000000005f39ba3dabaaaa3eabaa2a3f000000003ffe9abdabaa2a3f0000803f00000000ade5e4bc000080"
           "3f00000000abaaaa3e00000080abaaaabeabaaaa3eabaaaa3eb79b0ebc5374396261645f616c6c6f634862ed3babaaaa"
           "3e0000803fabaaaa3e6c492f3babaa2a3f00000000abaa2a3f00000080abaa2abfabaaaa3eabaa2a3fb6000060f00000"
           "3977aa2a3fabaa2a3f1a27983d000000000000803fabaa2a3fd1b3e03cabaaaa3e000000000000803f00000000000080"
           "bfabaaaa3e0000803f884cd33cabaa2abfabaa2a3f0000803fdfdcafbcabaaaabe0000803f0000803fe4db01bc000000"
           "000300000000010000000500000003000000000500000004000000030100000002000000060000000301000000060000"
           "000500000003020000000300000007000000030200000007000000060000000304000000050000000900000003040000"
           "0009000000080000000305000000060000000a00000003050000000a000000090000000306000000070000000b000000"
           "03060000000b0000000a0000000308000000090000000d00000003080000000d0000000c00000003090000000a000000"
           "0e00000003090000000e0000000d000000030a0000000b0000000f000000030a0000000f0000000e000000"),
       Expect::Either},

      // --- found by fuzz_ply in CI (scripts/fuzz.sh under UBSan): an ASCII face index written as a
      // huge real (8.5e32) was converted to long long before any range check, which is undefined
      // behaviour. It must be rejected as "expected a number".
      {"ply_ascii_index_as_huge_real", FileFormat::Ply,
       ply_header("ascii", "element vertex 3\n" + ply_xyz +
                               "element face 1\nproperty list uchar int vertex_indices\n") +
           kTriangleVerts + "3 0 1 8.55556e+32\n",
       Expect::Reject},
      {"ply_ascii_index_as_integral_real", FileFormat::Ply,
       ply_header("ascii", "element vertex 3\n" + ply_xyz +
                               "element face 1\nproperty list uchar int vertex_indices\n") +
           kTriangleVerts + "3 0 1 2.0\n",
       Expect::Either},

      // --- found by fuzz_ply in CI: an ASCII PLY declaring double coordinates held one beyond the
      // float range, and the default float writer wrote "inf", which the reader then refused. The
      // float writer must refuse it (qem::Error); the double writer must keep it exactly.
      {"ply_double_coordinate_beyond_float", FileFormat::Ply,
       ply_header("ascii",
                  "element vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
                  "element face 1\nproperty list uchar int vertex_indices\n") +
           "1e300 0 0\n1 0 0\n0 1 -1.7976931348623157e308\n3 0 1 2\n",
       Expect::Either},
      {"ply_double_property_beyond_float", FileFormat::Ply,
       ply_header("ascii", "element vertex 3\n" + ply_xyz +
                               "property double q\n"
                               "element face 1\nproperty list uchar int vertex_indices\n") +
           "0 0 0 1e300\n1 0 0 inf\n0 1 0 -5e-324\n3 0 1 2\n",
       Expect::Either},

      // --- OBJ ---------------------------------------------------------------------------------
      {"obj_face_without_vertices", FileFormat::Obj, "f 1 2 3\n", Expect::Reject},
      {"obj_index_zero", FileFormat::Obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", Expect::Reject},
      {"obj_negative_index_before_start", FileFormat::Obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n",
       Expect::Reject},
      {"obj_index_beyond_32_bits", FileFormat::Obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 4294967297 1 2\n",
       Expect::Reject},
      {"obj_coordinate_overflows", FileFormat::Obj, "v 1e999 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
       Expect::Reject},
      {"obj_nan_coordinate", FileFormat::Obj, "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", Expect::Reject},
      {"obj_missing_coordinate", FileFormat::Obj, "v 1 2\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", Expect::Reject},
      {"obj_backslash_at_end_of_file", FileFormat::Obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \\",
       Expect::Either},
      {"obj_long_number", FileFormat::Obj, "v " + std::string(5000, '9') + " 0 0\n", Expect::Either},
      {"obj_nul_bytes", FileFormat::Obj, std::string("v 0 0 0\0\nf 1\0 1 1\n", 18), Expect::Either},

      // --- PLY ---------------------------------------------------------------------------------
      {"ply_huge_vertex_count_without_data", FileFormat::Ply,
       ply_header("binary_little_endian", "element vertex 4294967295\n" + ply_xyz), Expect::Reject},
      {"ply_huge_face_count_without_data", FileFormat::Ply,
       ply_header("ascii", "element vertex 3\n" + ply_xyz +
                               "element face 2147483647\nproperty list uchar int vertex_indices\n") +
           kTriangleVerts,
       Expect::Reject},
      {"ply_truncated_binary_list", FileFormat::Ply,
       ply_header("binary_little_endian",
                  "element vertex 0\nelement face 1\nproperty list uchar int vertex_indices\n") +
           std::string(1, char(255)) + le32(0),
       Expect::Reject},
      {"ply_negative_ascii_index", FileFormat::Ply,
       ply_header("ascii", "element vertex 3\n" + ply_xyz +
                               "element face 1\nproperty list uchar int vertex_indices\n") +
           kTriangleVerts + "3 0 -1 2\n",
       Expect::Reject},
      {"ply_no_end_header", FileFormat::Ply, "ply\nformat ascii 1.0\nelement vertex 3\n" + ply_xyz,
       Expect::Reject},
      {"ply_float_list_indices", FileFormat::Ply,
       ply_header("ascii", "element vertex 3\n" + ply_xyz +
                               "element face 1\nproperty list uchar float vertex_indices\n") +
           kTriangleVerts + "3 0 1.5 2\n",
       Expect::Either},
      {"ply_unknown_type", FileFormat::Ply,
       ply_header("ascii", "element vertex 3\nproperty quad x\nproperty float y\nproperty float z\n") +
           kTriangleVerts,
       Expect::Reject},
      {"ply_list_count_type_int_huge", FileFormat::Ply,
       ply_header("binary_little_endian",
                  "element vertex 0\nelement face 1\nproperty list uint int vertex_indices\n") +
           le32(0xffffffffu),
       Expect::Reject},

      // --- STL ---------------------------------------------------------------------------------
      {"stl_binary_claims_a_billion_triangles", FileFormat::Stl, binary_stl(1000000000u, {}), Expect::Reject},
      {"stl_binary_nan_vertex", FileFormat::Stl, binary_stl(1, {{nan, 0, 0, 1, 0, 0, 0, 1, 0}}),
       Expect::Reject},
      {"stl_ascii_truncated_facet", FileFormat::Stl,
       "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n", Expect::Reject},
      {"stl_header_only", FileFormat::Stl, std::string(80, 'x'), Expect::Reject},
      {"stl_solid_word_but_binary", FileFormat::Stl,
       [] {
         std::string s = binary_stl(1, {{0, 0, 0, 1, 0, 0, 0, 1, 0}});
         s.replace(0, 6, "solid ");
         return s;
       }(),
       Expect::Either},

      // --- OFF ---------------------------------------------------------------------------------
      {"off_negative_count", FileFormat::Off, "OFF\n-1 2 0\n", Expect::Reject},
      {"off_index_out_of_range", FileFormat::Off, "OFF\n3 1 0\n" + kTriangleVerts + "3 0 1 5\n",
       Expect::Reject},
      {"off_huge_polygon", FileFormat::Off, "OFF\n3 1 0\n" + kTriangleVerts + "1000000000 0 1 2\n",
       Expect::Reject},
      {"off_huge_vertex_count", FileFormat::Off, "OFF\n99999999999 1 0\n", Expect::Reject},
      {"off_two_corner_face", FileFormat::Off, "OFF\n3 1 0\n" + kTriangleVerts + "2 0 1\n", Expect::Either},
      {"off_empty", FileFormat::Off, "", Expect::Reject},
  };
}

class ParserRegression : public testing::TestWithParam<ParserCase> {};

TEST_P(ParserRegression, ErrorOrValidMesh) {
  const ParserCase& c = GetParam();
  std::string problem;
  try {
    problem = fuzz::check_parse(c.bytes, c.format);
  } catch (const std::exception& e) {
    FAIL() << "exception other than qem::Error: " << e.what();
  }
  EXPECT_EQ(problem, "");
  if (c.expect == Expect::Reject) {
    EXPECT_THROW(parse_mesh(c.bytes, c.format, c.name), Error);
  }
}

INSTANTIATE_TEST_SUITE_P(Fuzz, ParserRegression, testing::ValuesIn(parser_cases()),
                         [](const testing::TestParamInfo<ParserCase>& info) {
                           return std::string(info.param.name);
                         });

// --- the simplifier ----------------------------------------------------------------------------

struct SimplifyBytes {
  const char* name;
  std::vector<std::uint8_t> bytes;
};

std::vector<SimplifyBytes> simplify_cases() {
  return {
      // All bytes zero: the lattice flavour puts every vertex at the same point.
      {"all_vertices_coincident", std::vector<std::uint8_t>(300, 0)},
      // Face target 0 on a coarse lattice, optimal placement, strict inversion checks.
      {"coarse_lattice_face_target_zero",
       {0x01, 0x40, 0x00, 0, 0, 0x00, 0, 200, 0x00, 0x05, 1, 2, 3, 4, 5, 6, 7, 8, 0, 1, 2,
        3,    4,    5,    6, 7, 8,    0, 1,   2,    3,    4, 5, 6, 7, 8, 0, 1, 2, 3, 4, 5,
        6,    7,    8,    0, 1, 2,    3, 4,   5,    6,    7, 8, 0, 1, 2, 3, 4, 5, 6, 7, 8}},
      // Raw doubles (flavour 2) with a vertex target and the distance threshold on.
      {"raw_doubles_threshold",
       {0x04, 0x7f, 0x03, 0x01, 0x02, 0x03, 0xff, 0x7f, 0x00, 0x80, 0x02, 0x10, 0xff, 0xff, 0xff,
        0xff, 0xff, 0xff, 0xef, 0x7f, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xaa, 0xbb,
        0xcc, 0xdd, 0xee, 0xff, 0x00, 0x3f, 0x12, 0x34, 0x56, 0x78, 0x9a, 0xbc, 0xde, 0xf0}},
      // Invalid option path (misc bits 0xC0): must be a qem::Error or a valid result.
      {"invalid_option", {0x02, 0x10, 0x80, 0x00, 0x00, 0xc1, 0x10, 0x00, 0x00, 0x00, 0x01, 0x05, 0x00}},
  };
}

class SimplifyRegression : public testing::TestWithParam<SimplifyBytes> {};

TEST_P(SimplifyRegression, ValidDeterministicResult) {
  const auto& bytes = GetParam().bytes;
  const fuzz::SimplifyCase c = fuzz::decode_simplify_case(bytes.data(), bytes.size());
  SimplifyResult first;
  try {
    first = simplify(c.mesh, c.options);
  } catch (const Error&) {
    return;  // the documented rejection of invalid options
  }
  EXPECT_EQ(fuzz::check_simplify_result(c, first), "");
  SimplifyResult second = simplify(c.mesh, c.options);
  EXPECT_EQ(first.mesh.indices, second.mesh.indices);
  EXPECT_EQ(first.mesh.positions, second.mesh.positions);
}

INSTANTIATE_TEST_SUITE_P(Fuzz, SimplifyRegression, testing::ValuesIn(simplify_cases()),
                         [](const testing::TestParamInfo<SimplifyBytes>& info) {
                           return std::string(info.param.name);
                         });

TEST(FuzzDecoder, DecodesEveryInputIntoAValidCase) {
  // The decoder itself must never produce out-of-range indices, whatever the bytes.
  std::vector<std::uint8_t> bytes;
  for (int n = 0; n < 200; ++n) {
    bytes.push_back(std::uint8_t(n * 37 + 11));
    fuzz::SimplifyCase c = fuzz::decode_simplify_case(bytes.data(), bytes.size());
    ASSERT_EQ(fuzz::check_mesh(c.mesh), "") << "after " << bytes.size() << " bytes";
    ASSERT_GE(c.mesh.vertex_count(), 3u);
  }
}

}  // namespace
}  // namespace qem
