// The scene files in scenes/, read by the render tests.
#pragma once

#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

namespace mcp::test {

inline const std::string kScenes = std::string(MCPLAY_SOURCE_DIR) + "/scenes";

/// The whole text of a file ("" when it cannot be read).
inline std::string read(const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

/// scenes/<name>.json, parsed.
inline nlohmann::json scene_json(const std::string& name) {
    return nlohmann::json::parse(read(kScenes + "/" + name + ".json"));
}

} // namespace mcp::test
