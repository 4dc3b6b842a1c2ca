// libFuzzer: multi-plane voting (segmentPlanes) on arbitrary correspondences.
#include <vector>

#include "fuzz_input.h"
#include "mono_plane_detection/planes/homography_voting.h"

using namespace mono_plane_detection;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in(data, size);
  std::vector<cv::Point2d> a, b;
  while (in.left() >= 16 && a.size() < 300) {
    a.push_back(in.nextPoint());
    b.push_back(in.nextPoint());
  }
  PlaneParams params;
  params.groups.max_tries = 500;
  const PlaneSegmentation s = segmentPlanes(a, b, params);
  if (!s.labels.empty() && s.labels.size() != a.size()) __builtin_trap();
  for (int label : s.labels)
    if (label < 0 || label > static_cast<int>(s.planes.size())) __builtin_trap();
  return 0;
}
