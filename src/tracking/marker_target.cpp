#include "mono_plane_detection/tracking/marker_target.h"

#include <opencv2/aruco.hpp>
#include <opencv2/core/version.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <utility>
#include <vector>

namespace mono_plane_detection {
namespace {

// OpenCV's predefined dictionaries by name (the names of cv::aruco::PREDEFINED_DICTIONARY_NAME).
const std::vector<std::pair<std::string, int>>& dictionaries() {
  static const std::vector<std::pair<std::string, int>> names{
      {"DICT_4X4_50", cv::aruco::DICT_4X4_50},
      {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
      {"DICT_4X4_250", cv::aruco::DICT_4X4_250},
      {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000},
      {"DICT_5X5_50", cv::aruco::DICT_5X5_50},
      {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
      {"DICT_5X5_250", cv::aruco::DICT_5X5_250},
      {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000},
      {"DICT_6X6_50", cv::aruco::DICT_6X6_50},
      {"DICT_6X6_100", cv::aruco::DICT_6X6_100},
      {"DICT_6X6_250", cv::aruco::DICT_6X6_250},
      {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000},
      {"DICT_7X7_50", cv::aruco::DICT_7X7_50},
      {"DICT_7X7_100", cv::aruco::DICT_7X7_100},
      {"DICT_7X7_250", cv::aruco::DICT_7X7_250},
      {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000},
      {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL},
  };
  return names;
}

int dictionaryId(const std::string& name) {
  for (const auto& [n, id] : dictionaries())
    if (n == name) return id;
  return -1;
}

// The aruco API changed in OpenCV 4.7 (cv::aruco::ArucoDetector, Dictionary by value,
// generateImageMarker). Noetic has 4.2, Debian 12 4.6: the old functions, and the new
// ones from 4.7 on.
#if CV_VERSION_MAJOR > 4 || (CV_VERSION_MAJOR == 4 && CV_VERSION_MINOR >= 7)
#define MPD_ARUCO_NEW_API 1
#endif

}  // namespace

std::string markerParamsError(const TargetParams& params) {
  if (dictionaryId(params.dictionary) < 0)
    return "dictionary '" + params.dictionary + "' is not an OpenCV aruco dictionary (e.g. DICT_4X4_50)";
  // The dictionary's size is in its name's last number (DICT_4X4_50: ids 0-49).
  const std::string& d = params.dictionary;
  const size_t underscore = d.find_last_of('_');
  if (d != "DICT_ARUCO_ORIGINAL" && underscore != std::string::npos) {
    const int size = std::stoi(d.substr(underscore + 1));
    if (params.marker_id < 0 || params.marker_id >= size)
      return "marker_id " + std::to_string(params.marker_id) + " is not in " + d + " (0-" +
             std::to_string(size - 1) + ")";
  }
  return {};
}

TargetDetection detectMarkerTarget(const cv::Mat& gray, const TargetParams& params) {
  TargetDetection out;
  if (gray.empty() || gray.type() != CV_8UC1 || gray.cols < 16 || gray.rows < 16) {
    out.rejection = TargetRejection::kBadImage;
    out.reason = "needs a non-empty 8-bit grey image of at least 16x16";
    return out;
  }
  if (const std::string error = markerParamsError(params); !error.empty()) {
    out.rejection = TargetRejection::kBadImage;
    out.reason = error;
    return out;
  }
  std::vector<std::vector<cv::Point2f>> corners, refused;
  std::vector<int> ids;
#ifdef MPD_ARUCO_NEW_API
  cv::aruco::DetectorParameters detector_params;
  detector_params.cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
  const cv::aruco::ArucoDetector detector(
      cv::aruco::getPredefinedDictionary(dictionaryId(params.dictionary)), detector_params);
  detector.detectMarkers(gray, corners, ids, refused);
#else
  const cv::Ptr<cv::aruco::Dictionary> dictionary =
      cv::aruco::getPredefinedDictionary(dictionaryId(params.dictionary));
  const cv::Ptr<cv::aruco::DetectorParameters> detector_params =
      cv::aruco::DetectorParameters::create();
  // Sub-pixel corners: the map's scale comes from them.
  detector_params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
  cv::aruco::detectMarkers(gray, dictionary, corners, ids, detector_params, refused);
#endif
  for (size_t k = 0; k < ids.size(); ++k) {
    if (ids[k] != params.marker_id || corners[k].size() != 4) continue;
    // aruco gives top-left, top-right, bottom-right, bottom-left of the printed marker;
    // the map frame starts at the bottom-left and turns the other way.
    const auto& c = corners[k];
    out.corners = {c[3], c[2], c[1], c[0]};
    out.found = true;
    out.contrast = 0;
    return out;
  }
  out.rejection = TargetRejection::kNoMarker;
  std::ostringstream why;
  why << "no marker " << params.marker_id << " of " << params.dictionary;
  if (!ids.empty()) {
    why << " (saw id";
    for (int id : ids) why << " " << id;
    why << ")";
  } else if (!refused.empty()) {
    why << " (" << refused.size() << " square candidates did not decode: too small, blurred?)";
  }
  out.reason = why.str();
  out.rejected[static_cast<int>(TargetRejection::kNoMarker)] = 1;
  return out;
}

cv::Mat drawMarkerImage(const TargetParams& params, int side_px, int margin_px) {
  cv::Mat marker;
  if (!markerParamsError(params).empty() || side_px < 8) return marker;
#ifdef MPD_ARUCO_NEW_API
  cv::aruco::generateImageMarker(cv::aruco::getPredefinedDictionary(dictionaryId(params.dictionary)),
                                 params.marker_id, side_px, marker, 1);
#else
  cv::aruco::drawMarker(cv::aruco::getPredefinedDictionary(dictionaryId(params.dictionary)),
                        params.marker_id, side_px, marker, 1);
#endif
  if (margin_px > 0)
    cv::copyMakeBorder(marker, marker, margin_px, margin_px, margin_px, margin_px,
                       cv::BORDER_CONSTANT, cv::Scalar(255));
  return marker;
}

}  // namespace mono_plane_detection
