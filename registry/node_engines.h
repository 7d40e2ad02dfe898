// The engines hosted by Node (docs/engines.md): WebAssembly builds from the
// npm registry, each a small program engines/node/<name>.mjs on the shared
// host engines/node/host/protocol.mjs. The harness runs them through the
// external protocol's machinery (external/external_simulator.h) in session
// mode, so a worker process pays Node's start-up and the engine's load once,
// and any failure costs only their own row; in every report they are engines
// like the compiled ones, told apart only by `source` and their settings.
#pragma once

#include "external/external_simulator.h"
#include "simulators/simulator.h"

#include <memory>
#include <span>
#include <string_view>
#include <vector>

namespace bouncecheck {

// What a Node-hosted engine is, known without starting it (`list`): its npm
// packages and versions are those engines/node/package-lock.json pins
// (tests/test_node_engines.cpp holds them equal to the files' own).
struct NodeEngine {
    std::string_view name;         // the simulator, and its file engines/node/<name>.mjs
    std::string_view description;  // the engine, its packages and versions, its precision
    bool runs_2d, runs_3d;
    double typical_ns_per_step;    // the engine's own step (Simulator::typical_ns_per_step)
};

std::span<const NodeEngine> node_engines();

// The simulators of node_engines(), in that order, each program within `limits`.
std::vector<std::unique_ptr<const Simulator>> make_node_engine_simulators(ExternalLimits limits);

}  // namespace bouncecheck
