// The worker-process pool the sweep and the stress suite run their pairs in:
// every pair once, in long-lived workers; a crash, an exception or a hang
// costs its own pair only; large results arrive whole.
#include "platform/parallel_pairs.h"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <unistd.h>

using namespace bouncecheck;

namespace {

struct Ended {
    PairOutcome outcome;
    std::size_t done = 0;
};

// Runs the pairs of simulators x items and keeps what became of each.
std::map<std::pair<std::size_t, std::size_t>, Ended> run_all(
    std::size_t simulators, std::size_t items, int jobs,
    std::function<std::string(std::size_t, std::size_t)> run, double deadline = 0) {
    std::map<std::pair<std::size_t, std::size_t>, Ended> ended;
    PairSchedule schedule;
    schedule.jobs = jobs;
    schedule.cost = [](std::size_t, std::size_t item) { return static_cast<double>(item); };
    schedule.deadline_seconds = deadline;
    schedule.run = std::move(run);
    schedule.finished = [&](std::size_t sim, std::size_t item, const PairOutcome& o, std::size_t done, std::size_t) {
        EXPECT_TRUE(ended.emplace(std::pair(sim, item), Ended{o, done}).second) << "pair ended twice";
    };
    run_pairs_in_parallel(simulators, items, schedule);
    return ended;
}

std::string pid_and(std::size_t sim, std::size_t item) {
    return std::to_string(::getpid()) + " " + std::to_string(sim) + "," + std::to_string(item);
}

}  // namespace

TEST(ParallelPairs, EveryPairOnceInLongLivedWorkerProcesses) {
    const auto ended = run_all(3, 20, 2, pid_and);
    ASSERT_EQ(ended.size(), 60u);
    std::set<std::string> workers;
    std::set<std::size_t> dones;
    for (const auto& [pair, e] : ended) {
        ASSERT_EQ(e.outcome.kind, PairOutcome::Kind::ok) << e.outcome.failure;
        const std::string& p = e.outcome.payload;
        const std::string pid = p.substr(0, p.find(' '));
        EXPECT_NE(pid, std::to_string(::getpid())) << "the pair ran in this process";
        EXPECT_EQ(p.substr(p.find(' ') + 1), std::to_string(pair.first) + "," + std::to_string(pair.second));
        workers.insert(pid);
        dones.insert(e.done);
    }
    // Two workers for 60 pairs: started once, not per pair.
    EXPECT_EQ(workers.size(), 2u);
    EXPECT_EQ(dones.size(), 60u);
    EXPECT_EQ(*dones.begin(), 1u);
    EXPECT_EQ(*dones.rbegin(), 60u);
}

TEST(ParallelPairs, TheCostliestPairsStartFirst) {
    std::vector<std::pair<std::size_t, std::size_t>> order;
    PairSchedule schedule;
    schedule.jobs = 1;
    schedule.cost = [](std::size_t sim, std::size_t item) { return sim == 1 ? 100.0 + item : static_cast<double>(item); };
    schedule.run = pid_and;
    schedule.finished = [&](std::size_t sim, std::size_t item, const PairOutcome&, std::size_t, std::size_t) {
        order.emplace_back(sim, item);
    };
    run_pairs_in_parallel(2, 3, schedule);
    const std::vector<std::pair<std::size_t, std::size_t>> expected{{1, 2}, {1, 1}, {1, 0}, {0, 2}, {0, 1}, {0, 0}};
    EXPECT_EQ(order, expected);
}

TEST(ParallelPairs, AnAbortCostsItsOwnPairAndTheWorkerIsReplaced) {
    const auto ended = run_all(2, 6, 2, [](std::size_t sim, std::size_t item) -> std::string {
        if (sim == 1 && item == 3) {
            std::fputs("engine: assertion failed: contact count\n", stderr);
            std::abort();
        }
        return pid_and(sim, item);
    });
    ASSERT_EQ(ended.size(), 12u);
    for (const auto& [pair, e] : ended) {
        if (pair == std::pair<std::size_t, std::size_t>(1, 3)) {
            EXPECT_EQ(e.outcome.kind, PairOutcome::Kind::crashed);
            EXPECT_NE(e.outcome.failure.find("signal 6"), std::string::npos) << e.outcome.failure;
            EXPECT_NE(e.outcome.failure.find("assertion failed: contact count"), std::string::npos)
                << e.outcome.failure;
        } else {
            EXPECT_EQ(e.outcome.kind, PairOutcome::Kind::ok) << e.outcome.failure;
        }
    }
}

TEST(ParallelPairs, AnExceptionIsACrashWithItsMessageAndTheWorkerGoesOn) {
    std::set<std::string> workers;
    const auto ended = run_all(1, 5, 1, [](std::size_t sim, std::size_t item) -> std::string {
        if (item == 2) throw std::runtime_error("solver exploded");
        return pid_and(sim, item);
    });
    for (const auto& [pair, e] : ended) {
        if (pair.second == 2) {
            EXPECT_EQ(e.outcome.kind, PairOutcome::Kind::crashed);
            EXPECT_EQ(e.outcome.failure, "exception: solver exploded");
        } else {
            ASSERT_EQ(e.outcome.kind, PairOutcome::Kind::ok);
            workers.insert(e.outcome.payload.substr(0, e.outcome.payload.find(' ')));
        }
    }
    EXPECT_EQ(workers.size(), 1u) << "an exception does not cost the worker";
}

TEST(ParallelPairs, AWorkerThatExitsIsACrashWithItsStatus) {
    const auto ended = run_all(1, 2, 1, [](std::size_t sim, std::size_t item) -> std::string {
        if (item == 0) std::_Exit(7);
        return pid_and(sim, item);
    });
    ASSERT_EQ(ended.size(), 2u);
    EXPECT_EQ(ended.at({0, 0}).outcome.kind, PairOutcome::Kind::crashed);
    EXPECT_EQ(ended.at({0, 0}).outcome.failure, "its worker process exited with status 7");
    EXPECT_EQ(ended.at({0, 1}).outcome.kind, PairOutcome::Kind::ok);
}

TEST(ParallelPairs, AHangIsKilledByTheWatchdogAndReportedHung) {
    const auto start = std::chrono::steady_clock::now();
    const auto ended = run_all(1, 4, 2, [](std::size_t sim, std::size_t item) -> std::string {
        if (item == 1)
            for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));  // a step that never returns
        return pid_and(sim, item);
    }, 0.3);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_EQ(ended.size(), 4u);
    for (const auto& [pair, e] : ended) {
        if (pair.second == 1) {
            EXPECT_EQ(e.outcome.kind, PairOutcome::Kind::hung);
            EXPECT_NE(e.outcome.failure.find("over the limit of 0.3 s"), std::string::npos) << e.outcome.failure;
        } else {
            EXPECT_EQ(e.outcome.kind, PairOutcome::Kind::ok) << e.outcome.failure;
        }
    }
    EXPECT_LT(seconds, 5.0) << "the hung pair held the pool up";
}

TEST(ParallelPairs, AWorkerThatIgnoresSigtermIsKilled) {
    const auto ended = run_all(1, 1, 1, [](std::size_t, std::size_t) -> std::string {
        std::signal(SIGTERM, SIG_IGN);
        for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
    }, 0.1);
    ASSERT_EQ(ended.size(), 1u);
    EXPECT_EQ(ended.begin()->second.outcome.kind, PairOutcome::Kind::hung);
}

TEST(ParallelPairs, LargeResultsArriveWhole) {
    const auto ended = run_all(1, 3, 2, [](std::size_t, std::size_t item) {
        std::string big(3'000'000 + item, '\0');
        for (std::size_t i = 0; i < big.size(); ++i) big[i] = static_cast<char>((i * 131 + item) % 251);
        return big;
    });
    for (const auto& [pair, e] : ended) {
        ASSERT_EQ(e.outcome.kind, PairOutcome::Kind::ok);
        const std::string& big = e.outcome.payload;
        ASSERT_EQ(big.size(), 3'000'000 + pair.second);
        bool same = true;
        for (std::size_t i = 0; i < big.size() && same; ++i)
            same = big[i] == static_cast<char>((i * 131 + pair.second) % 251);
        EXPECT_TRUE(same) << "item " << pair.second;
    }
}

TEST(ParallelPairs, NoPairsAndMoreJobsThanPairs) {
    EXPECT_TRUE(run_all(0, 5, 2, pid_and).empty());
    EXPECT_TRUE(run_all(3, 0, 2, pid_and).empty());
    EXPECT_EQ(run_all(1, 1, 16, pid_and).size(), 1u);
}

// How every `finished` handler reads a pair (run, sweep, stress): decoded
// when it ended ok, else crashed or hung with the pool's reason, and a
// payload the decoder rejects is a failure of its own, not a crash label.
TEST(ParallelPairs, DecodePairGivesTheResultOrWhyThereIsNone) {
    std::string decoded;
    const auto keep = [&](const std::string& payload) { decoded = payload; };
    EXPECT_FALSE(decode_pair(PairOutcome{PairOutcome::Kind::ok, "bytes", ""}, keep).has_value());
    EXPECT_EQ(decoded, "bytes");

    const auto crashed = decode_pair(PairOutcome{PairOutcome::Kind::crashed, "", "signal 6 (Aborted)"}, keep);
    ASSERT_TRUE(crashed.has_value());
    EXPECT_EQ(crashed->kind, PairFailure::Kind::crashed);
    EXPECT_EQ(crashed->reason, "signal 6 (Aborted)");
    EXPECT_EQ(crashed->labelled(), "crashed: signal 6 (Aborted)");

    const auto hung = decode_pair(PairOutcome{PairOutcome::Kind::hung, "", "no result after 2 s"}, keep);
    ASSERT_TRUE(hung.has_value());
    EXPECT_EQ(hung->kind, PairFailure::Kind::hung);
    EXPECT_EQ(hung->labelled(), "hung: no result after 2 s");

    decoded.clear();
    const auto unreadable = decode_pair(PairOutcome{PairOutcome::Kind::ok, "garbage", ""},
                                        [](const std::string&) { throw std::runtime_error("truncated"); });
    ASSERT_TRUE(unreadable.has_value());
    EXPECT_EQ(unreadable->kind, PairFailure::Kind::unreadable);
    EXPECT_EQ(unreadable->reason, "its worker process sent an unreadable result: truncated");
    EXPECT_EQ(unreadable->labelled(), unreadable->reason);
}
