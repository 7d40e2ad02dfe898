// Two paths timed side by side, once each per benchmark iteration, in
// alternating order: load that drifts over seconds moves both runs of a
// pair alike and cancels in their ratio, which separate benchmarks' medians
// cannot do on a shared machine.
#pragma once

#include "simulators/simulator.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace bouncecheck::bench {

struct PairedSeconds {
    std::vector<double> first, second;  // per iteration, wall-clock seconds
};

template <class First, class Second>
PairedSeconds time_pairs(benchmark::State& state, First&& first, Second&& second) {
    PairedSeconds out;
    for (auto _ : state) {
        double a = 0, b = 0;
        if (out.first.size() % 2 == 0) {
            a = timed_seconds(first);
            b = timed_seconds(second);
        } else {
            b = timed_seconds(second);
            a = timed_seconds(first);
        }
        out.first.push_back(a);
        out.second.push_back(b);
    }
    return out;
}

inline double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
}

}  // namespace bouncecheck::bench
