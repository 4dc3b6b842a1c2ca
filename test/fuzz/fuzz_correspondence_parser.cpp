// libFuzzer: the segment_planes input parser on arbitrary text.
#include <sstream>
#include <string>

#include "mono_plane_detection/planes/correspondence_io.h"

using namespace mono_plane_detection;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  const Correspondences c = readCorrespondences(in);
  if (c.view1.size() != c.view2.size()) __builtin_trap();
  if (!c.error.empty() && c.error_line < 1) __builtin_trap();
  return 0;
}
