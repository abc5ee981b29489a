// The record file (docs/record-format.md): a fixed 48-byte header, the base mesh, then one
// variable-length entry per contraction. Little endian whatever the host; every size the header
// announces is checked against the bytes present before anything is allocated, so a lying or
// truncated file fails with a message and never with a huge allocation.
#include <cstring>
#include <string>

#include "io/io_common.h"
#include "qem/progressive.h"

namespace qem {

namespace {

constexpr char kMagic[8] = {'Q', 'E', 'M', 'R', 'E', 'C', '\x1a', '\n'};
constexpr std::size_t kHeaderBytes = 48;
constexpr std::size_t kVertexBytes = 24;       // x, y, z float64
constexpr std::size_t kFaceBytes = 12;         // 3 x uint32
constexpr std::size_t kContractionBytes = 44;  // kept, removed, x, y, z, error, dead count
constexpr std::size_t kDeadBytes = 4;          // one uint32 face id

void put_u32(std::string& out, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) out.push_back(char((v >> (8 * k)) & 0xff));
}
void put_u64(std::string& out, std::uint64_t v) {
  for (int k = 0; k < 8; ++k) out.push_back(char((v >> (8 * k)) & 0xff));
}
void put_f64(std::string& out, double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  put_u64(out, bits);
}

// A bounds-checked little-endian reader; the caller has verified the total size already, so a
// failure here means an internal inconsistency (dead counts not adding up), reported as such.
class Reader {
 public:
  Reader(std::string_view bytes, const std::string& name) : p_(bytes), name_(name) {}
  std::size_t offset() const { return at_; }
  std::uint32_t u32() {
    need(4);
    std::uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v |= std::uint32_t(std::uint8_t(p_[at_ + k])) << (8 * k);
    at_ += 4;
    return v;
  }
  std::uint64_t u64() {
    need(8);
    std::uint64_t v = 0;
    for (int k = 0; k < 8; ++k) v |= std::uint64_t(std::uint8_t(p_[at_ + k])) << (8 * k);
    at_ += 8;
    return v;
  }
  double f64() {
    const std::uint64_t bits = u64();
    double v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }

 private:
  void need(std::size_t n) {
    if (p_.size() - at_ < n)
      io::fail(name_,
               "truncated at byte " + std::to_string(at_) + " (dead face counts exceed the header's total)");
  }
  std::string_view p_;
  std::size_t at_ = 0;
  const std::string& name_;
};

}  // namespace

std::string serialize_record(const Record& r) {
  validate_record(r);
  const std::size_t nv = r.base.vertex_count(), nf = r.base.face_count(), nc = r.size();
  std::string out;
  out.reserve(kHeaderBytes + kVertexBytes * nv + kFaceBytes * nf + kContractionBytes * nc +
              kDeadBytes * r.dead_faces.size());
  out.append(kMagic, sizeof kMagic);
  put_u32(out, kRecordVersion);
  put_u32(out, r.double_input ? kRecordFlagDoubleInput : 0);
  put_u64(out, nv);
  put_u64(out, nf);
  put_u64(out, nc);
  put_u64(out, r.dead_faces.size());
  for (double x : r.base.positions) put_f64(out, x);
  for (std::uint32_t i : r.base.indices) put_u32(out, i);
  for (std::size_t i = 0; i < nc; ++i) {
    put_u32(out, r.kept[i]);
    put_u32(out, r.removed[i]);
    for (int k = 0; k < 3; ++k) put_f64(out, r.position[3 * i + k]);
    put_f64(out, r.error[i]);
    put_u32(out, r.dead_begin[i + 1] - r.dead_begin[i]);
    for (std::uint32_t k = r.dead_begin[i]; k < r.dead_begin[i + 1]; ++k) put_u32(out, r.dead_faces[k]);
  }
  return out;
}

Record parse_record(std::string_view bytes, const std::string& name) {
  if (bytes.size() < kHeaderBytes)
    io::fail(name, "truncated header: " + std::to_string(bytes.size()) + " bytes, a record starts with " +
                       std::to_string(kHeaderBytes));
  if (std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) io::fail(name, "not a qem record (bad magic)");
  Reader in(bytes, name);
  in.u64();  // magic
  const std::uint32_t version = in.u32();
  if (version != kRecordVersion)
    io::fail(name, "unsupported record version " + std::to_string(version) + " (this qem reads version " +
                       std::to_string(kRecordVersion) + ")");
  const std::uint32_t flags = in.u32();
  if (flags & ~kRecordFlagDoubleInput)
    io::fail(name, "unknown flags " + std::to_string(flags & ~kRecordFlagDoubleInput) + " in the header");
  const std::uint64_t nv = in.u64(), nf = in.u64(), nc = in.u64(), nd = in.u64();
  if (nv > 0xffffffffu) io::fail(name, "vertex count " + std::to_string(nv) + " exceeds 32-bit ids");
  if (nf > 0xffffffffu) io::fail(name, "face count " + std::to_string(nf) + " exceeds 32-bit ids");
  // Each contraction removes one vertex and each face dies at most once.
  if (nc > nv) io::fail(name, "more contractions (" + std::to_string(nc) + ") than vertices");
  if (nd > nf) io::fail(name, "more dead faces (" + std::to_string(nd) + ") than faces");
  // All four counts are now below 2^32, so the expected size fits in 64 bits without overflow.
  const std::uint64_t expected =
      kHeaderBytes + kVertexBytes * nv + kFaceBytes * nf + kContractionBytes * nc + kDeadBytes * nd;
  if (bytes.size() < expected)
    io::fail(name, "truncated: the header announces " + std::to_string(expected) + " bytes, the file has " +
                       std::to_string(bytes.size()));
  if (bytes.size() > expected)
    io::fail(name, std::to_string(bytes.size() - expected) + " unexpected bytes after the last contraction");

  Record r;
  r.double_input = flags & kRecordFlagDoubleInput;
  r.base.positions.resize(3 * nv);
  for (double& x : r.base.positions) x = in.f64();
  r.base.indices.resize(3 * nf);
  for (std::uint32_t& i : r.base.indices) i = in.u32();
  r.kept.resize(nc);
  r.removed.resize(nc);
  r.position.resize(3 * nc);
  r.error.resize(nc);
  r.dead_begin.assign(nc + 1, 0);
  r.dead_faces.reserve(nd);
  for (std::size_t i = 0; i < nc; ++i) {
    r.kept[i] = in.u32();
    r.removed[i] = in.u32();
    for (int k = 0; k < 3; ++k) r.position[3 * i + k] = in.f64();
    r.error[i] = in.f64();
    const std::uint32_t dead = in.u32();
    if (dead > nd - r.dead_faces.size())
      io::fail_element(
          name, "contraction", i,
          "dead face count " + std::to_string(dead) + " exceeds the header's total of " + std::to_string(nd));
    for (std::uint32_t k = 0; k < dead; ++k) r.dead_faces.push_back(in.u32());
    r.dead_begin[i + 1] = std::uint32_t(r.dead_faces.size());
  }
  if (r.dead_faces.size() != nd)
    io::fail(name, "the contractions list " + std::to_string(r.dead_faces.size()) +
                       " dead faces, the header announces " + std::to_string(nd));
  validate_record(r, name);
  return r;
}

void write_record(const std::string& path, const Record& record) {
  io::write_file_atomic(path, serialize_record(record));
}

Record read_record(const std::string& path) {
  io::FileData file(path);
  return parse_record(file.bytes(), path);
}

}  // namespace qem
