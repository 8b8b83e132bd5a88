#pragma once

// What the tool tests share: a temporary folder per test file, running a tool of the package.
#include <stdlib.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <string>

namespace act_color_tool_test {

// "/tmp/<name>_XXXXXX", made at the first call for that name.
inline std::string tempDir(const std::string& name) {
  static std::map<std::string, std::string> dirs;
  std::string& dir = dirs[name];
  if (dir.empty()) {
    std::string pattern = "/tmp/" + name + "_XXXXXX";
    dir = mkdtemp(&pattern[0]);
  }
  return dir;
}

inline std::string readText(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

inline bool exists(const std::string& path) { return static_cast<bool>(std::ifstream(path)); }

struct ToolRun {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

// Runs the package's `tool` (from ACT_TOOLS_DIR) with `arguments`, its output logged in `dir`.
inline ToolRun runTool(const std::string& tool, const std::string& arguments, const std::string& dir) {
  const std::string log = dir + "/log.txt";
  const std::string command = std::string(ACT_TOOLS_DIR) + "/" + tool + " " + arguments + " > " + log + " 2>&1";
  const int status = std::system(command.c_str());
  ToolRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.output = readText(log);
  return r;
}

}  // namespace act_color_tool_test
