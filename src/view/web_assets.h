// Where the viewer's built page (web/dist: index.html, app.js, style.css) is found at run time,
// and writing a page + scene to a folder. The C++ build never needs npm: the page is built
// separately (`npm run build` in web/) and looked up, in this order:
//   1. $QEM_WEB_DIR
//   2. <folder of the qem executable>/web            (a copy placed next to the binary)
//   3. <folder of the qem executable>/../share/qem/web  (an installed tree)
//   4. the source tree's web/dist, from the QEM_WEB_DIST_DIR compile definition if set
//   5. <folder of the qem executable>/../web/dist    (build/qem inside the source tree)
#pragma once

#include <map>
#include <string>
#include <vector>

namespace qem::view {

/// Files keyed by path relative to the page root ("index.html", "data/scene.json").
using FileSet = std::map<std::string, std::string>;

/// The folder of the running executable (/proc/self/exe's), empty when unknown.
std::string executable_dir();

/// The folders searched for the built page, in order (see above).
std::vector<std::string> web_asset_candidates();

/// The first candidate holding index.html and app.js. Throws qem::Error listing the folders
/// searched and how to build the page when none does.
std::string find_web_assets();

/// Every regular file under `dir` (recursively), keyed by its relative path with '/' separators.
FileSet read_tree(const std::string& dir);

/// Writes the files under `dir`, creating folders as needed. Throws qem::Error on failure.
void write_tree(const std::string& dir, const FileSet& files);

/// The Content-Type for a file name (by extension).
const char* content_type(const std::string& path);

}  // namespace qem::view
