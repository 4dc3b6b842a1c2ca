// libFuzzer: the start-up target detector on arbitrary small images.
#include <opencv2/core.hpp>

#include "fuzz_input.h"
#include "mono_plane_detection/tracking/target_detector.h"

using namespace mono_plane_detection;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 2) return 0;
  const int cols = 1 + data[0] % 96, rows = 1 + data[1] % 96;
  cv::Mat image(rows, cols, CV_8UC1, cv::Scalar(0));
  for (size_t i = 2; i < size && i - 2 < image.total(); ++i) image.data[i - 2] = data[i];
  TargetParams params;
  params.min_area_px = 20;  // small images: let candidates through to the later checks
  const TargetDetection d = detectTarget(image, params);
  if (d.found) {
    for (const auto& c : d.corners)
      if (!(c.x >= -1 && c.y >= -1 && c.x <= cols && c.y <= rows)) __builtin_trap();
    cameraPoseFromTarget(d, cv::Matx33d(100, 0, cols / 2.0, 0, 100, rows / 2.0, 0, 0, 1),
                         cv::Mat(), params);
  }
  return 0;
}
