#include "platform/install_layout.h"

#include <cstdlib>
#include <system_error>

namespace fs = std::filesystem;

namespace bouncecheck {

namespace {

bool is_existing_directory(const fs::path& dir) {
    std::error_code ec;
    return !dir.empty() && fs::is_directory(dir, ec);
}

// `relative` to the binary's folder, normalised, if it is a directory.
fs::path beside_binary(const char* relative) {
    const fs::path dir = executable_dir();
    if (dir.empty()) return {};
    const fs::path candidate = (dir / relative).lexically_normal();
    return is_existing_directory(candidate) ? candidate : fs::path();
}

}  // namespace

fs::path executable_dir() {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    return ec ? fs::path() : exe.parent_path();
}

fs::path engine_module_dir() {
    static const fs::path dir = [] {
        if (fs::path installed = beside_binary(kInstalledEngineDir); !installed.empty()) return installed;
        if (fs::path built = beside_binary("engines"); !built.empty()) return built;
        return fs::path(BOUNCECHECK_ENGINE_MODULE_DIR);
    }();
    return dir;
}

fs::path node_engine_dir() {
    if (fs::path installed = beside_binary(kInstalledNodeEngineDir); !installed.empty()) return installed;
    return BOUNCECHECK_NODE_ENGINE_SOURCE_DIR;
}

fs::path bundled_scenario_dir() {
    if (const char* dir = std::getenv("BOUNCECHECK_SCENARIOS")) return dir;
    if (fs::path installed = beside_binary(kInstalledScenarioDir); !installed.empty()) return installed;
    return BOUNCECHECK_SCENARIO_DIR;
}

}  // namespace bouncecheck
