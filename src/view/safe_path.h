// Resolving a file that a model names (an OBJ's material library, a texture, a glTF buffer or
// image URI) inside the model's folder only. `qem view` serves such files to the browser; a
// reference like "../../.ssh/id_rsa", an absolute path or a symbolic link leading out of the
// folder must never make it serve a file the model's folder does not hold.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace qem::view {

struct ResolvedFile {
  std::string key;             ///< the path relative to the folder, '/' separated, normalised
  std::filesystem::path file;  ///< where it is on disk
};

/// The regular file `ref` names relative to `folder` (backslashes read as '/'), when it lies
/// inside `folder` both by its name (no absolute path, no ".." out of it) and on disk (symbolic
/// links resolved). Otherwise nullopt, with the reason in `why`.
std::optional<ResolvedFile> resolve_inside(const std::filesystem::path& folder, const std::string& ref,
                                           std::string* why);

/// Decodes %XX escapes (glTF URIs are URI references: "my%20texture.png").
std::string percent_decode(const std::string& uri);

}  // namespace qem::view
