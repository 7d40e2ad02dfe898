#include "reports/provenance.h"

#include "registry/registry.h"

#include "git_state.h"  // generated at every build (cmake/git_state.cmake)

#include <fmt/format.h>

#include <ctime>
#include <fstream>
#include <sstream>
#include <thread>

namespace bouncecheck {

namespace {

std::string& command_line() {
    static std::string line;
    return line;
}

std::string cpu_model() {
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("model name", 0) != 0) continue;
        const auto colon = line.find(':');
        if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
    return "unknown";
}

std::string utc_now() {
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    ::gmtime_r(&now, &utc);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
    return text;
}

// BOUNCECHECK_ENGINE_PACKAGES: "name=package version|..." as CMake read it
// from dpkg at configure time (CMakeLists.txt).
std::string package_of(const std::string& simulator) {
    std::stringstream list(BOUNCECHECK_ENGINE_PACKAGES);
    for (std::string entry; std::getline(list, entry, '|');) {
        const auto eq = entry.find('=');
        if (eq != std::string::npos && entry.substr(0, eq) == simulator) return entry.substr(eq + 1);
    }
    return {};
}

}  // namespace

void set_command_line(int argc, const char* const* argv) {
    std::string line;
    for (int i = 0; i < argc; ++i) {
        if (i > 0) line += ' ';
        line += argv[i];
    }
    command_line() = line;
}

Provenance this_provenance(bool with_machine) {
    Provenance p;
    p.build.version = BOUNCECHECK_VERSION;
    p.build.git_commit = BOUNCECHECK_GIT_COMMIT;
    p.build.git_dirty = BOUNCECHECK_GIT_DIRTY;
    p.build.compiler = BOUNCECHECK_COMPILER;
    p.build.build_type = BOUNCECHECK_BUILD_TYPE;
    p.build.flags = BOUNCECHECK_CXX_FLAGS;
    for (const auto& sim : built_simulators()) {
        if (!sim->third_party()) continue;
        const std::string name(sim->name());
        p.build.engines.push_back({name, std::string(sim->description()), package_of(name)});
    }
    if (with_machine) p.machine = Provenance::Machine{cpu_model(), std::thread::hardware_concurrency(), utc_now(), command_line()};
    return p;
}

nlohmann::json to_json(const Provenance& p) {
    nlohmann::json engines = nlohmann::json::array();
    for (const auto& e : p.build.engines)
        engines.push_back({{"simulator", e.simulator},
                           {"library", e.library},
                           {"package", e.package.empty() ? nlohmann::json(nullptr) : nlohmann::json(e.package)}});
    nlohmann::json j = {{"build",
                         {{"bouncecheck_version", p.build.version},
                          {"git_commit", p.build.git_commit.empty() ? nlohmann::json(nullptr) : nlohmann::json(p.build.git_commit)},
                          {"git_dirty", p.build.git_dirty},
                          {"compiler", p.build.compiler},
                          {"build_type", p.build.build_type},
                          {"flags", p.build.flags},
                          {"engines", engines}}}};
    if (p.machine)
        j["machine"] = {{"cpu", p.machine->cpu},
                        {"cores", p.machine->cores},
                        {"date", p.machine->date},
                        {"command_line", p.machine->command_line}};
    return j;
}

std::string format_provenance(const nlohmann::json& j) {
    // Read from a report on disk: any field may be missing or of another type.
    if (!j.is_object() || !j.contains("build") || !j["build"].is_object())
        return "unknown (the report has no provenance)";
    const nlohmann::json& b = j["build"];
    const auto text = [](const nlohmann::json& o, const char* key) {
        return o.contains(key) && o[key].is_string() ? o[key].get<std::string>() : std::string("?");
    };
    std::string commit = b.contains("git_commit") && b["git_commit"].is_string()
                             ? "git " + b["git_commit"].get<std::string>().substr(0, 12)
                             : std::string("no git commit");
    if (b.contains("git_dirty") && b["git_dirty"].is_boolean() && b["git_dirty"].get<bool>()) commit += "+dirty";
    std::string line = fmt::format("bouncecheck {} ({}, {}, {})", text(b, "bouncecheck_version"), commit,
                                   text(b, "compiler"), text(b, "build_type"));
    if (j.contains("machine") && j["machine"].is_object()) {
        const nlohmann::json& m = j["machine"];
        const std::string cores =
            m.contains("cores") && m["cores"].is_number_unsigned() ? std::to_string(m["cores"].get<unsigned>()) : "?";
        line += fmt::format(" on {} ({} cores), {}", text(m, "cpu"), cores, text(m, "date"));
    }
    return line;
}

std::string format_provenance(const Provenance& p) { return format_provenance(to_json(p)); }

}  // namespace bouncecheck
