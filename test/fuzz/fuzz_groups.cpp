// libFuzzer: the five-point invariants and the group builder on arbitrary floats.
#include <vector>

#include "fuzz_input.h"
#include "mono_plane_detection/planes/coplanar_groups.h"
#include "mono_plane_detection/planes/cross_ratio.h"

using namespace mono_plane_detection;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in(data, size);
  std::vector<cv::Point2d> a, b;
  while (in.left() >= 16 && a.size() < 200) {
    a.push_back(in.nextPoint());
    b.push_back(in.nextPoint());
  }
  if (a.size() >= 5) {
    const std::array<cv::Point2d, 5> p{a[0], a[1], a[2], a[3], a[4]};
    const std::array<cv::Point2d, 5> q{b[0], b[1], b[2], b[3], b[4]};
    const auto ia = fivePointInvariants(p);
    const auto ib = fivePointInvariants(q);
    if (ia && ib) invariantDistance(*ia, *ib);
    wellSpread(p, 0.01);
  }
  GroupParams params;
  params.max_tries = 500;
  buildGroups(a, params, 20);
  findCoplanarGroups(a, b, params);
  return 0;
}
