#include "mono_plane_detection/eval/segmentation_error.h"

#include <algorithm>

namespace mono_plane_detection {

double misclassificationError(const std::vector<int>& truth, const std::vector<int>& found) {
  if (truth.empty() || truth.size() != found.size()) return truth.empty() ? 0.0 : 1.0;
  const int T = *std::max_element(truth.begin(), truth.end());
  const int F = *std::max_element(found.begin(), found.end());
  std::vector<std::vector<int>> count(F + 1, std::vector<int>(T + 1, 0));
  for (size_t i = 0; i < truth.size(); ++i) {
    if (truth[i] >= 0 && found[i] >= 0) ++count[found[i]][truth[i]];
  }
  // Best one-to-one matching of found planes 1..F to true planes 1..T: dynamic
  // programming over the set of true planes already used (T is small).
  const int masks = 1 << T;
  std::vector<int> best(masks, -1), next(masks, -1);
  best[0] = 0;
  for (int fp = 1; fp <= F; ++fp) {
    next = best;  // found plane fp matched to nothing
    for (int m = 0; m < masks; ++m) {
      if (best[m] < 0) continue;
      for (int tp = 1; tp <= T; ++tp) {
        const int bit = 1 << (tp - 1);
        if (m & bit) continue;
        next[m | bit] = std::max(next[m | bit], best[m] + count[fp][tp]);
      }
    }
    best.swap(next);
  }
  const int correct = count[0][0] + *std::max_element(best.begin(), best.end());
  return 1.0 - static_cast<double>(correct) / truth.size();
}

}  // namespace mono_plane_detection
