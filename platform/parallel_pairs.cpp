#include "platform/parallel_pairs.h"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <mutex>
#include <utility>
#include <vector>

namespace bouncecheck {

void run_pairs_in_parallel(std::size_t simulators, std::size_t items, const PairSchedule& schedule) {
    using Pair = std::pair<std::size_t, std::size_t>;  // (simulator, item)
    std::vector<std::vector<Pair>> tasks;
    std::vector<Pair> single;
    for (std::size_t sim = 0; sim < simulators; ++sim) {
        const bool serial = schedule.serial && schedule.serial(sim);
        std::vector<Pair> group;
        for (std::size_t item = 0; item < items; ++item) (serial ? group : single).emplace_back(sim, item);
        if (serial) tasks.push_back(std::move(group));
    }
    std::stable_sort(single.begin(), single.end(),
                     [&](const Pair& a, const Pair& b) { return schedule.cost(a.second) > schedule.cost(b.second); });
    for (const Pair& p : single) tasks.push_back({p});

    std::mutex lock;
    std::size_t done = 0;
    const int jobs = schedule.jobs > 0 ? schedule.jobs : tbb::info::default_concurrency();
    tbb::task_arena arena(jobs);
    arena.execute([&] {
        tbb::parallel_for(
            tbb::blocked_range<std::size_t>(0, tasks.size(), 1),
            [&](const tbb::blocked_range<std::size_t>& range) {
                for (std::size_t t = range.begin(); t != range.end(); ++t) {
                    for (const auto& [sim, item] : tasks[t]) {
                        schedule.run(sim, item);
                        std::lock_guard guard(lock);
                        ++done;
                        if (schedule.finished) schedule.finished(sim, item, done);
                    }
                }
            },
            tbb::simple_partitioner());
    });
}

}  // namespace bouncecheck
