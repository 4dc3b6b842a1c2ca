// Reading two-view correspondences: one per line "x1 y1 x2 y2" (pixels, view 1 then
// view 2), '#' starts a comment, blank lines are skipped.
#pragma once

#include <cstddef>
#include <istream>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace mono_plane_detection {

struct Correspondences {
  std::vector<cv::Point2d> view1, view2;
  std::string error;   // empty when the whole input was read; otherwise names the line
  int error_line = 0;  // 1-based line of the error
};

// Longest line read, comment included. The input is read as a stream, one line at a
// time, so memory stays bounded by this whatever the file holds (a 1 GB line took 17 GB
// when every token was copied before the fields were counted).
constexpr std::size_t kMaxCorrespondenceLineBytes = 64 * 1024;

// Stops at the first malformed line: longer than kMaxCorrespondenceLineBytes, not
// exactly four numbers, a number that is not finite (subnormals are finite), a NUL byte
// inside a number, or trailing text.
Correspondences readCorrespondences(std::istream& in);

}  // namespace mono_plane_detection
