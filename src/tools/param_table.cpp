// Prints the parameter tables: `param_table --markdown` is docs/parameters.md,
// `param_table --cfg` is cfg/Planes.cfg (dynamic_reconfigure).
#include <cstring>
#include <iostream>

#include "mono_plane_detection/params/param_table.h"

int main(int argc, char** argv) {
  if (argc == 2 && std::strcmp(argv[1], "--markdown") == 0) {
    std::cout << mono_plane_detection::parametersMarkdown();
    return 0;
  }
  if (argc == 2 && std::strcmp(argv[1], "--cfg") == 0) {
    std::cout << mono_plane_detection::dynamicReconfigureCfg();
    return 0;
  }
  std::cerr << "usage: param_table --markdown   (prints docs/parameters.md)\n"
               "       param_table --cfg        (prints cfg/Planes.cfg)\n";
  return 2;
}
