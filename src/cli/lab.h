// The sampler lab's commands of the command line: points, analyze, warp-test (docs/sampler-lab.md).
#pragma once

#include <string>
#include <vector>

namespace mcp::cli {

/// Finds a scene (a path, or a name in the scenes directory) and reads it; on failure prints why
/// and returns false (main.cpp's load_scene).
using LoadScene = bool (*)(const std::string& arg, const std::string& dir_arg, std::string* path,
                           std::string* text);

int cmd_points(const std::vector<std::string>& args);
int cmd_analyze(const std::vector<std::string>& args);
int cmd_warp_test(const std::vector<std::string>& args, LoadScene load_scene);

} // namespace mcp::cli
