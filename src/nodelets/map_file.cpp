#include "map_file.h"

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "plane_messages.h"

namespace mono_plane_detection {

MapFileResult writeMapFile(const PlaneArray* planes, const std::string& path) {
  MapFileResult result;
  if (path.empty()) {
    result.message = "no path given";
    return result;
  }
  if (planes == nullptr) {
    result.message = "no map yet";
    return result;
  }
  std::error_code error;
  const std::filesystem::path absolute = std::filesystem::absolute(path, error);
  const std::filesystem::path target = error ? std::filesystem::path(path) : absolute;
  std::ofstream out(target);
  const int open_errno = out ? 0 : errno;  // (meaningful right after the open only)
  out << planesYaml(*planes);
  out.close();
  if (!out) {
    result.message = "cannot write " + target.string() + " (" +
                     (open_errno ? std::error_code(open_errno, std::generic_category()).message()
                                 : std::string("write failed")) +
                     ")";
    return result;
  }
  result.success = true;
  for (const auto& p : planes->planes) result.planes += p.metric;
  result.message = "wrote " + std::to_string(result.planes) + " planes to " + target.string();
  return result;
}

}  // namespace mono_plane_detection
