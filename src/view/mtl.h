// The part of an OBJ material library (.mtl, Wavefront) that the viewer shows: each material's
// diffuse colour (Kd), opacity (d, or Tr = 1 - d) and diffuse texture (map_Kd). Everything else
// (specular, illumination models, bump maps) is skipped: the page draws Lambert surfaces.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace qem::view {

struct MtlMaterial {
  std::string name;                     ///< `newmtl`
  double diffuse[3] = {0.8, 0.8, 0.8};  ///< `Kd`, sRGB (the .mtl default is 0.8 grey in most tools)
  double opacity = 1;                   ///< `d`, or 1 - `Tr`
  std::string diffuse_map;              ///< `map_Kd` file name as written (options removed), "" when none
};

/// Parses .mtl text. Lenient like the tools that write it: unknown statements and malformed
/// numbers are skipped (a note goes to `warnings` as "<name>, line N: ..."), never an error.
std::vector<MtlMaterial> parse_mtl(std::string_view text, const std::string& name,
                                   std::vector<std::string>* warnings);

}  // namespace qem::view
