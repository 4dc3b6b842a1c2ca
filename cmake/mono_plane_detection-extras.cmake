# Exported to every package that finds mono_plane_detection: its headers use C++17
# (std::optional, std::variant), and Noetic's GCC 9 compiles C++ as gnu++14 by default.
# A standard set lower than 17 (or none) is raised; a higher one is kept.
if(NOT CMAKE_CXX_STANDARD OR CMAKE_CXX_STANDARD EQUAL 98 OR CMAKE_CXX_STANDARD LESS 17)
  set(CMAKE_CXX_STANDARD 17)
  set(CMAKE_CXX_STANDARD_REQUIRED ON)
endif()
