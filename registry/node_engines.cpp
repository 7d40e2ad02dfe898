#include "registry/node_engines.h"

#include "engines/engine.h"
#include "external/external_simulator.h"
#include "platform/install_layout.h"
#include "platform/program.h"

#include <fmt/format.h>

#include <filesystem>
#include <span>

namespace fs = std::filesystem;

namespace bouncecheck {

namespace {

// Typical costs: the engines' own steps for one ball, measured under Node
// (docs/engines.md); they order the parallel schedule, nothing else.
constexpr NodeEngine kNodeEngines[] = {
    {"rapier", "Rapier 0.21.0 (npm @dimforge/rapier3d-compat and rapier2d-compat 0.21.0, WebAssembly), f32, 3D and 2D",
     true, true, 25000},
    {"jolt", "Jolt Physics 5 (npm jolt-physics 1.1.0, WebAssembly), f32, 3D", false, true, 9000},
    {"physx", "PhysX 5.6.1 (npm physx-js-webidl 2.7.3, WebAssembly), f32, 3D", false, true, 18000},
    {"havok", "Havok (npm @babylonjs/havok 1.3.14, WebAssembly), f32, 3D", false, true, 12000},
    {"box2d3", "Box2D v3.1 (npm box2d3-wasm 5.2.0, WebAssembly), f32, 2D", true, false, 27000},
    {"mujoco3", "MuJoCo 3.3.8 (npm mujoco-js 0.0.7, WebAssembly), f64, 3D and 2D", true, true, 5000},
    // The web's own (docs/engines.md, the web's engines).
    {"planck", "planck.js 1.4.2 (npm planck 1.4.2, Box2D 2 ported to JavaScript), f64, 2D", true, false, 7000},
    {"p2", "p2 (npm p2-es 1.2.3, JavaScript), f64, 2D", true, false, 4000},
    {"oimo", "Oimo.js 1.0.9 (npm oimo 1.0.9, JavaScript), f64, 3D", false, true, 4000},
    {"cannon", "cannon-es 0.20.0 (npm cannon-es 0.20.0, JavaScript), f64, 3D", false, true, 6000},
    {"ammo", "Bullet 2.82 as asm.js (npm ammo.js 0.0.10), f32, 3D", false, true, 7000},
    {"matter", "matter-js 0.20.0 (npm matter-js 0.20.0, JavaScript), f64, 2D", true, false, 9000},
    {"box2d-wasm", "Box2D 2.4.1, the compiled box2d's version (npm box2d-wasm 7.0.0, WebAssembly), f32, 2D", true, false,
     1500},
};

class NodeEngineSimulator final : public Simulator {
public:
    NodeEngineSimulator(const NodeEngine& engine, ExternalLimits limits)
        : engine_(engine),
          script_(node_engine_dir() / fmt::format("{}.mjs", engine.name)),
          origin_(fmt::format("node: {}", script_.string())),
          hosted_(make_external_simulator(declaration(), limits)) {}

    std::string_view name() const override { return engine_.name; }
    std::string_view description() const override { return engine_.description; }
    std::string_view origin() const override { return origin_; }
    bool third_party() const override { return true; }
    bool runs_in_own_program() const override { return true; }
    double typical_ns_per_step() const override { return engine_.typical_ns_per_step; }

    std::optional<std::string> cannot_run(const Scenario& s) const override {
        if (s.dim == 3 && !engine_.runs_3d) return fmt::format("{} is a 2D engine: it cannot run a 3D scenario", name());
        if (s.dim == 2 && !engine_.runs_2d) return fmt::format("{} cannot run a 2D scenario", name());
        std::error_code ec;
        if (!fs::exists(script_.parent_path() / "node_modules", ec))
            return fmt::format("{} is missing: run scripts/setup.sh (npm ci in engines/node/)",
                               (script_.parent_path() / "node_modules").string());
        if (!resolve_program("node", {}))
            return "Node.js is not on PATH: the Node-hosted engines need `node` (Debian's nodejs; scripts/setup.sh "
                   "installs it)";
        return std::nullopt;
    }

    RunOutcome run(const Scenario& s, RunSink& sink) const override {
        RunOutcome out = hosted_->run(s, sink);
        if (s.engine_options(std::string(name())).tangential_unset)
            out.settings.insert(out.settings.begin(), tangential_unset_setting());
        return out;
    }

private:
    // `node <name>.mjs --session`: one Node process per worker answers
    // scenario after scenario, its engine loaded once.
    ExternalDeclaration declaration() const {
        ExternalDeclaration d(std::string(engine_.name), {"node", script_.string(), "--session"});
        d.session = true;
        d.builtin_engine = true;
        d.origin = origin_;
        return d;
    }

    const NodeEngine& engine_;
    fs::path script_;
    std::string origin_;
    std::unique_ptr<const Simulator> hosted_;
};

}  // namespace

std::span<const NodeEngine> node_engines() { return kNodeEngines; }

std::vector<std::unique_ptr<const Simulator>> make_node_engine_simulators(ExternalLimits limits) {
    std::vector<std::unique_ptr<const Simulator>> all;
    for (const NodeEngine& engine : kNodeEngines) all.push_back(std::make_unique<NodeEngineSimulator>(engine, limits));
    return all;
}

}  // namespace bouncecheck
