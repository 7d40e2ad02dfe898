// libFuzzer target for an output folder's manifest (platform/output_manifest.h),
// the one file bouncecheck reads back from a folder it writes into and acts
// on (it removes what the manifest lists). parse_manifest must answer every
// input with a manifest or a "line N: reason" error; an accepted manifest
// must list only paths inside the folder, and print back to text that parses
// to the same entries. Anything else is a finding.
#include "platform/output_manifest.h"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <variant>

namespace {

[[noreturn]] void finding(const char* what, const std::string& detail) {
    std::fprintf(stderr, "fuzz_output_manifest: %s\n%s\n", what, detail.c_str());
    std::abort();
}

void check_path(const std::string& path) {
    if (path.empty() || path.front() == '/') finding("accepted an empty or absolute path", path);
    if (path == ".." || path.rfind("../", 0) == 0 || path.find("/../") != std::string::npos ||
        (path.size() >= 3 && path.compare(path.size() - 3, 3, "/..") == 0))
        finding("accepted a path leaving the folder", path);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    const auto parsed = bouncecheck::parse_manifest(text);
    if (const auto* error = std::get_if<std::string>(&parsed)) {
        // "N: reason", N a line number
        const std::size_t colon = error->find(": ");
        if (colon == 0 || colon == std::string::npos || error->find_first_not_of("0123456789") != colon)
            finding("an error that does not start with its line", *error);
        return 0;
    }
    const auto& manifest = std::get<bouncecheck::Manifest>(parsed);
    for (const auto& e : manifest.entries) check_path(e.path);
    const auto again = bouncecheck::parse_manifest(bouncecheck::format_manifest(manifest));
    if (!std::holds_alternative<bouncecheck::Manifest>(again))
        finding("a manifest printed back does not parse", std::get<std::string>(again));
    const auto& back = std::get<bouncecheck::Manifest>(again);
    if (back.entries.size() != manifest.entries.size()) finding("printed back, the entries changed in number", "");
    for (std::size_t i = 0; i < back.entries.size(); ++i) {
        const auto &a = manifest.entries[i], &b = back.entries[i];
        if (a.kind != b.kind || a.size != b.size || a.digest != b.digest || a.path != b.path)
            finding("printed back, an entry changed", a.path);
    }
    return 0;
}
