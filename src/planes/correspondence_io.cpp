#include "mono_plane_detection/planes/correspondence_io.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace mono_plane_detection {
namespace {

// Whitespace-separated tokens of a line without its comment.
std::vector<std::string> tokens(const std::string& line) {
  const std::string data = line.substr(0, line.find('#'));
  std::istringstream in(data);
  std::vector<std::string> out;
  for (std::string t; in >> t;) out.push_back(t);
  return out;
}

bool parseNumber(const std::string& token, double& value) {
  errno = 0;
  char* end = nullptr;
  value = std::strtod(token.c_str(), &end);
  return end && *end == '\0' && errno == 0 && std::isfinite(value);
}

}  // namespace

Correspondences readCorrespondences(std::istream& in) {
  Correspondences out;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::vector<std::string> t = tokens(line);
    if (t.empty()) continue;
    if (t.size() != 4) {
      out.error = "line " + std::to_string(number) +
                  ": expected 4 numbers \"x1 y1 x2 y2\", found " + std::to_string(t.size()) +
                  " fields";
      out.error_line = number;
      return out;
    }
    double v[4];
    for (int k = 0; k < 4; ++k) {
      if (!parseNumber(t[k], v[k])) {
        out.error = "line " + std::to_string(number) + ": '" + t[k] + "' is not a finite number";
        out.error_line = number;
        return out;
      }
    }
    out.view1.emplace_back(v[0], v[1]);
    out.view2.emplace_back(v[2], v[3]);
  }
  return out;
}

}  // namespace mono_plane_detection
