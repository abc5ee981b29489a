// OBJ material libraries, as far as the viewer draws them (mtl.h).
#include "view/mtl.h"

#include <cstdlib>
#include <string>

namespace qem::view {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::string_view next_token(std::string_view& s) {
  s = trim(s);
  std::size_t end = s.find_first_of(" \t");
  std::string_view t = s.substr(0, end);
  s = end == std::string_view::npos ? std::string_view() : s.substr(end);
  return t;
}

bool parse_number(std::string_view t, double& out) {
  if (t.empty()) return false;
  std::string s(t);
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size();
}

// The texture options of the MTL format (Wavefront's spec, "Texture map options") with how many
// arguments each takes; -o, -s and -t take one to three numbers.
int option_arguments(std::string_view opt) {
  if (opt == "-blendu" || opt == "-blendv" || opt == "-bm" || opt == "-boost" || opt == "-cc" ||
      opt == "-clamp" || opt == "-imfchan" || opt == "-texres" || opt == "-type")
    return 1;
  if (opt == "-mm") return 2;
  if (opt == "-o" || opt == "-s" || opt == "-t") return 3;
  return -1;
}

// The file name of a `map_Kd` statement: the rest of the line once the options are removed
// (a name may hold spaces).
std::string map_file(std::string_view rest) {
  for (;;) {
    rest = trim(rest);
    std::string_view probe = rest;
    std::string_view opt = next_token(probe);
    const int n = opt.size() > 1 && opt.front() == '-' ? option_arguments(opt) : -1;
    if (n < 0) break;
    rest = probe;
    for (int i = 0; i < n; ++i) {
      std::string_view look = rest;
      std::string_view arg = next_token(look);
      double unused;
      // -o/-s/-t take up to three numbers; stop at the first word that is not one.
      if (n == 3 && i > 0 && !parse_number(arg, unused)) break;
      rest = look;
    }
  }
  return std::string(trim(rest));
}

}  // namespace

std::vector<MtlMaterial> parse_mtl(std::string_view text, const std::string& name,
                                   std::vector<std::string>* warnings) {
  std::vector<MtlMaterial> out;
  std::size_t line_no = 0;
  auto note = [&](const std::string& what) {
    if (warnings) warnings->push_back(name + ", line " + std::to_string(line_no) + ": " + what);
  };
  while (!text.empty()) {
    std::size_t nl = text.find('\n');
    std::string_view line = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view() : text.substr(nl + 1);
    ++line_no;
    if (std::size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    std::string_view rest = line;
    std::string_view key = next_token(rest);
    if (key.empty()) continue;
    if (key == "newmtl") {
      out.push_back({});
      out.back().name = std::string(trim(rest));
      continue;
    }
    if (key != "Kd" && key != "d" && key != "Tr" && key != "map_Kd") continue;
    if (out.empty()) {
      // (Built by append: GCC 12 warns falsely (-Wrestrict) on "'" + std::string.)
      note(std::string(key).append(" before any newmtl, skipped"));
      continue;
    }
    MtlMaterial& m = out.back();
    if (key == "map_Kd") {
      m.diffuse_map = map_file(rest);
      continue;
    }
    double v[3];
    int n = 0;
    for (std::string_view t = next_token(rest); !t.empty() && n < 3; t = next_token(rest))
      if (!parse_number(t, v[n++])) {
        n = -1;
        break;
      }
    if (key == "Kd") {
      // `Kd spectral file` and `Kd xyz x y z` are legal but rare: kept at the default.
      if (n == 1) v[1] = v[2] = v[0], n = 3;
      if (n == 3)
        for (int k = 0; k < 3; ++k) m.diffuse[k] = v[k];
      else
        note("Kd needs one or three numbers, skipped");
    } else if (n >= 1) {
      m.opacity = key == "d" ? v[0] : 1 - v[0];
    } else {
      note(std::string(key) + " needs a number, skipped");
    }
  }
  return out;
}

}  // namespace qem::view
