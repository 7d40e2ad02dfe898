#include "registry/engine_module.h"

#include "platform/install_layout.h"

#include <dlfcn.h>
#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <mutex>
#include <memory>
#include <string>
#include <utility>

namespace bouncecheck {
namespace {

// The loaded engine, or why there is none. Modules are never unloaded: the
// engine's code stays mapped until the process ends.
struct Loaded {
    std::unique_ptr<const Simulator> engine;
    std::string why_not;  // when there is no engine
};

std::string module_name(std::string_view folder) { return fmt::format("bouncecheck-engine-{}.so", folder); }

Loaded load(std::string_view module, std::string_view entry) {
    const std::string path = (engine_module_dir() / module).string();
    // RTLD_NOW: a symbol missing from the module fails here, with its name,
    // not in the middle of a run.
    void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) return {nullptr, fmt::format("cannot load the engine's module: {}", ::dlerror())};
    using Entry = const Simulator* (*)();
    const auto make = reinterpret_cast<Entry>(::dlsym(handle, std::string(entry).c_str()));
    if (!make) return {nullptr, fmt::format("the engine's module {} has no entry {}", path, entry)};
    return {std::unique_ptr<const Simulator>(make()), {}};
}

// One load per module and entry and process, whichever thread asks first.
const Loaded& loaded(const std::string& module, const std::string& entry) {
    static std::mutex mutex;
    static std::map<std::pair<std::string, std::string>, Loaded> engines;
    const std::lock_guard lock(mutex);
    auto it = engines.find({module, entry});
    if (it == engines.end()) it = engines.emplace(std::pair{module, entry}, load(module, entry)).first;
    return it->second;
}

class EngineInModule final : public Simulator {
public:
    EngineInModule(const EngineIdentity& identity, std::string_view folder)
        : identity_(identity),
          module_(module_name(folder)),
          entry_(fmt::format("bouncecheck_engine_{}", identity.name)) {
        std::replace(entry_.begin(), entry_.end(), '-', '_');
    }

    std::string_view name() const override { return identity_.name; }
    std::string_view description() const override { return identity_.description; }
    bool third_party() const override { return true; }
    double typical_ns_per_step() const override { return identity_.typical_ns_per_step; }

    std::optional<std::string> cannot_run(const Scenario& s) const override {
        const Loaded& loaded_engine = loaded(module_, entry_);
        if (!loaded_engine.engine) return loaded_engine.why_not;
        return loaded_engine.engine->cannot_run(s);
    }
    RunOutcome run(const Scenario& s, RunSink& sink) const override {
        const Loaded& loaded_engine = loaded(module_, entry_);
        if (!loaded_engine.engine) return {RunStatus::failed, loaded_engine.why_not, {}, 0, std::nullopt};
        return loaded_engine.engine->run(s, sink);
    }
    UnrecordedRun run_unrecorded(const Scenario& s) const override {
        const Loaded& loaded_engine = loaded(module_, entry_);
        if (!loaded_engine.engine) return {RunStatus::failed, loaded_engine.why_not, 0, {}, 0, std::nullopt};
        return loaded_engine.engine->run_unrecorded(s);
    }

private:
    EngineIdentity identity_;
    std::string module_, entry_;
};

}  // namespace

std::unique_ptr<const Simulator> engine_in_module(const EngineIdentity& identity, std::string_view folder) {
    return std::make_unique<EngineInModule>(identity, folder);
}

std::filesystem::path engine_module_file(std::string_view folder) { return engine_module_dir() / module_name(folder); }

}  // namespace bouncecheck
