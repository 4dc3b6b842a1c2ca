// Prints the parameter tables: `param_table --markdown` is docs/parameters.md.
#include <cstring>
#include <iostream>

#include "mono_plane_detection/params/param_table.h"

int main(int argc, char** argv) {
  if (argc == 2 && std::strcmp(argv[1], "--markdown") == 0) {
    std::cout << mono_plane_detection::parametersMarkdown();
    return 0;
  }
  std::cerr << "usage: param_table --markdown   (prints docs/parameters.md)\n";
  return 2;
}
