// Whether OpenCV's USAC framework (findFundamentalMat / findHomography with USAC_*) is
// used: from 4.5.2 on. USAC came with 4.5; 4.5.0-4.5.1 could crash on degenerate input
// (opencv/opencv#19639, fixed by #19640 for 4.5.2). Noetic's 4.2 takes the plain RANSAC.
// -DMPD_FORCE_PLAIN_RANSAC (CMAKE_CXX_FLAGS) builds the plain path on a newer OpenCV, to
// test it.
#pragma once

#include <opencv2/core/version.hpp>

#if !defined(MPD_FORCE_PLAIN_RANSAC) &&                                      \
    (CV_VERSION_MAJOR > 4 ||                                                 \
     (CV_VERSION_MAJOR == 4 &&                                               \
      (CV_VERSION_MINOR > 5 || (CV_VERSION_MINOR == 5 && CV_VERSION_REVISION >= 2))))
#define MPD_HAVE_USAC 1
#else
#define MPD_HAVE_USAC 0
#endif
