// libFuzzer target for the scenario loader: the bytes go through
// parse_scenario, the parse and validation that `bouncecheck validate` runs
// on a file's contents. The loader's contract is that nothing but
// ScenarioError escapes, whatever the input; anything else (another
// exception, a crash, a sanitizer report, a diagnostic that is not one
// located line) is a finding.
#include "scenarios/loader.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

namespace {

[[noreturn]] void finding(const char* what, const std::string& detail) {
    std::fprintf(stderr, "fuzz_scenario_loader: %s\n%s\n", what, detail.c_str());
    std::abort();
}

// What a loaded scenario promises the simulators (scenarios/scenario.h and the README).
void check_accepted(const bouncecheck::Scenario& s) {
    if (s.dim != 2 && s.dim != 3) finding("accepted a scenario of dimension", std::to_string(s.dim));
    if (!(s.radius >= 1e-9) || !(s.dt >= 1e-9) || !(s.duration > 0) || !(s.dt <= s.duration))
        finding("accepted a radius below 1 nm, a dt below 1 ns, or a non-positive duration", s.name);
    for (int i = 0; i < s.dim; ++i) {
        if (!(s.room[i] > 2 * s.radius)) finding("accepted a room side not larger than the ball", s.name);
        if (!(s.position[i] >= s.radius && s.position[i] <= s.room[i] - s.radius))
            finding("accepted a ball outside the room", s.name);
        if (!std::isfinite(s.velocity[i]) || !std::isfinite(s.gravity[i]))
            finding("accepted a non-finite vector", s.name);
    }
    if (!(s.alpha >= 0 && s.alpha <= 1 && s.beta >= 0 && s.beta <= 1))
        finding("accepted damping outside [0, 1]", s.name);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        check_accepted(bouncecheck::parse_scenario(text, "fuzz.toml"));
    } catch (const bouncecheck::ScenarioError& e) {
        if (e.diagnostics().empty()) finding("ScenarioError without a diagnostic", "");
        for (const bouncecheck::Diagnostic& d : e.diagnostics()) {
            const std::string line = d.format();
            // Each diagnostic is one located line: the CLI prints them one per line.
            if (d.file != "fuzz.toml" || d.reason.empty() || line.find('\n') != std::string::npos)
                finding("malformed diagnostic", line);
            if (d.line < 1 || d.column < 1) finding("diagnostic without a location", line);
        }
    } catch (const std::exception& e) {
        finding("an exception other than ScenarioError escaped", e.what());
    }
    return 0;
}
