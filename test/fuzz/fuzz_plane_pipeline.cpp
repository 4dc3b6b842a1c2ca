// libFuzzer: the plane stage (validation, pose, map) on arbitrary track frames.
#include <vector>

#include "fuzz_input.h"
#include "mono_plane_detection/mapping/plane_pipeline.h"

using namespace mono_plane_detection;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in(data, size);
  PipelineParams params;
  params.planes.groups.max_tries = 300;
  params.frame_gap = 1;
  PlanePipeline pipeline(params);
  pipeline.setCamera(cv::Matx33d(500, 0, 320, 0, 500, 240, 0, 0, 1), cv::Mat());
  for (int image = 0; image < 4 && !in.empty(); ++image) {
    TrackFrame f;
    f.stamp = 1000 + image * 0.033 + in.nextByte() * 0.001;
    f.size = {640, 480};
    const int n = in.nextByte() % 64;
    for (int i = 0; i < n; ++i) {
      f.ids.push_back(in.nextByte() % 80);  // repeats are likely: validation must catch them
      f.pixels.push_back(in.nextPoint());
      f.target_corner.push_back(in.nextByte() % 8 == 0);
    }
    if (!validateTrackFrame(f).empty()) continue;  // the nodelet drops these
    pipeline.process(f);
  }
  return 0;
}
