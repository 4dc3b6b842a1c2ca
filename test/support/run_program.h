// Test support: runs a program of the package and captures its exit code and output.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "support/temp_path.h"

namespace mono_plane_detection {

struct ProgramRun {
  int code;
  std::string out;  // standard output
  std::string err;  // standard error
};

inline ProgramRun runProgram(const std::string& program, const std::string& args) {
  const std::string err_path = tempPath("program_stderr.txt");
  FILE* pipe = popen((program + " " + args + " 2>" + err_path).c_str(), "r");
  ProgramRun run{-1, "", ""};
  if (!pipe) return run;
  char buffer[4096];
  for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;) run.out.append(buffer, n);
  const int status = pclose(pipe);
  run.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(err_path);
  std::stringstream text;
  text << in.rdbuf();
  run.err = text.str();
  return run;
}

inline std::string writeTempFile(const std::string& name, const std::string& text) {
  const std::string path = tempPath(name);
  std::ofstream(path) << text;
  return path;
}

}  // namespace mono_plane_detection
