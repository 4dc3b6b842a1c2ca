// Small helpers shared by the command-line programs: strict number parsing and the
// usage error (message, usage text, exit code 2).
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace mono_plane_detection {

// The whole text is one finite number.
inline bool parseNumber(const char* text, double& out) {
  char* end = nullptr;
  out = std::strtod(text, &end);
  return end != text && *end == '\0' && std::isfinite(out);
}

// The whole text is one integer.
inline bool parseInteger(const char* text, long& out) {
  char* end = nullptr;
  out = std::strtol(text, &end, 10);
  return end != text && *end == '\0';
}

inline int usageError(const char* program, const std::string& what, const char* usage) {
  std::fprintf(stderr, "%s: %s\n%s", program, what.c_str(), usage);
  return 2;
}

}  // namespace mono_plane_detection
