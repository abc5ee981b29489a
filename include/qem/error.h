// The one exception type of the public API: every failure a user can cause (bad file, bad option)
// is reported with it, with a message that names the file and the line or element.
#pragma once

#include <stdexcept>
#include <string>

namespace qem {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace qem
