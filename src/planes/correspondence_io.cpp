#include "mono_plane_detection/planes/correspondence_io.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <string_view>

namespace mono_plane_detection {
namespace {

// The whole token is one finite number. strtod's ERANGE on underflow is no error: a
// subnormal such as 1e-320 is finite; overflow gives infinity, refused by isfinite. A
// NUL inside the token ends strtod early and so is refused by the end check.
bool parseNumber(std::string_view token, double& value) {
  const std::string text(token);
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && !text.empty() && std::isfinite(value);
}

bool isBlank(char c) { return c != '\0' && std::isspace(static_cast<unsigned char>(c)); }

// The token as it can be shown in a message: at most 40 characters, control bytes escaped.
std::string printable(std::string_view token) {
  std::string out;
  for (size_t i = 0; i < token.size() && i < 40; ++i) {
    const unsigned char c = token[i];
    if (std::isprint(c)) {
      out += static_cast<char>(c);
    } else {
      static const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return token.size() > 40 ? out + "..." : out;
}

// Reads one line (without '\n') into `line`; false at the end of input. `too_long` when
// the line has more than the limit: the rest of it is skipped, never stored.
bool readLine(std::streambuf& in, std::string& line, bool& too_long) {
  line.clear();
  too_long = false;
  int c = in.sbumpc();
  if (c == std::char_traits<char>::eof()) return false;
  for (; c != std::char_traits<char>::eof() && c != '\n'; c = in.sbumpc()) {
    if (line.size() < kMaxCorrespondenceLineBytes)
      line += static_cast<char>(c);
    else
      too_long = true;
  }
  return true;
}

}  // namespace

Correspondences readCorrespondences(std::istream& in) {
  Correspondences out;
  auto fail = [&](int number, const std::string& what) {
    out.error = "line " + std::to_string(number) + ": " + what;
    out.error_line = number;
    return out;
  };
  std::streambuf* buffer = in.rdbuf();
  if (!buffer) return out;
  std::string line;
  bool too_long = false;
  for (int number = 1; readLine(*buffer, line, too_long); ++number) {
    if (too_long)
      return fail(number, "longer than " + std::to_string(kMaxCorrespondenceLineBytes) +
                              " bytes (expected \"x1 y1 x2 y2\")");
    const std::string_view data = std::string_view(line).substr(0, line.find('#'));
    // Count the fields without copying them; keep the first four.
    std::string_view fields[4];
    size_t count = 0;
    for (size_t i = 0; i < data.size();) {
      while (i < data.size() && isBlank(data[i])) ++i;
      if (i == data.size()) break;
      const size_t start = i;
      while (i < data.size() && !isBlank(data[i])) ++i;
      if (count < 4) fields[count] = data.substr(start, i - start);
      ++count;
    }
    if (count == 0) continue;
    if (count != 4)
      return fail(number, "expected 4 numbers \"x1 y1 x2 y2\", found " + std::to_string(count) +
                              " fields");
    double v[4];
    for (int k = 0; k < 4; ++k)
      if (!parseNumber(fields[k], v[k]))
        return fail(number, "'" + printable(fields[k]) + "' is not a finite number");
    out.view1.emplace_back(v[0], v[1]);
    out.view2.emplace_back(v[2], v[3]);
  }
  return out;
}

}  // namespace mono_plane_detection
