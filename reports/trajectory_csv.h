// `--trajectories` output: DIR/<scenario>/<simulator>.csv, header t,x,y,z,vx,vy,vz
// (2D: t,x,y,vx,vy), one row per state, every number with 17 significant
// digits so that it parses back to the same double.
#pragma once

#include "platform/atomic_file.h"
#include "simulators/state.h"

#include <filesystem>
#include <string>

namespace bouncecheck {

class TrajectoryCsv final : public StateSink {
public:
    TrajectoryCsv(const std::filesystem::path& target, int dim);
    void write(const State& s) override;
    void commit();  // the file appears only now, complete

private:
    void flush();
    AtomicFile file_;
    int dim_;
    std::string buffer_;
};

}  // namespace bouncecheck
