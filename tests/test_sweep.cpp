// The work-precision sweep: --dt parsing, the reference's observed order,
// independence of --jobs, skipped and failed pairs, and the command end to end.
#include "commands/sweep/sweep_pipeline.h"
#include "metrics/summary.h"
#include "reference/reference_simulator.h"
#include "registry/registry.h"
#include "scenarios/loader.h"
#include "simulators/simulator.h"
#include "tests/support/cli.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace bouncecheck;

namespace {

const std::string kScenarios = BOUNCECHECK_SCENARIO_DIR;

const Simulator* find_simulator(const std::vector<std::unique_ptr<const Simulator>>& all, std::string_view name) {
    for (const auto& sim : all)
        if (sim->name() == name) return sim.get();
    return nullptr;
}

TEST(SweepDtList, CommaList) {
    const DtParse p = parse_dt_list("0.03,0.015,1e-3");
    ASSERT_TRUE(p.error.empty()) << p.error;
    EXPECT_EQ(p.dts, (std::vector<double>{0.03, 0.015, 1e-3}));
    const DtParse one = parse_dt_list("0.01");
    ASSERT_TRUE(one.error.empty());
    EXPECT_EQ(one.dts, std::vector<double>{0.01});
}

TEST(SweepDtList, FromToFactor) {
    const DtParse p = parse_dt_list("0.03:0.0075:2");
    ASSERT_TRUE(p.error.empty()) << p.error;
    EXPECT_EQ(p.dts, (std::vector<double>{0.03, 0.015, 0.0075}));
    // Repeated division by 10 rounds; TO itself is still included.
    const DtParse tens = parse_dt_list("0.1:0.001:10");
    ASSERT_TRUE(tens.error.empty()) << tens.error;
    ASSERT_EQ(tens.dts.size(), 3u);
    EXPECT_NEAR(tens.dts.back(), 0.001, 1e-15);
    // TO between two steps: stops above it.
    const DtParse between = parse_dt_list("0.03:0.01:2");
    EXPECT_EQ(between.dts, (std::vector<double>{0.03, 0.015}));
}

TEST(SweepDtList, Errors) {
    for (const char* bad : {"", "0.03,", "0.03,,0.01", "abc", "0.03,-0.01", "0", "0.03,0", "nan", "inf", "1e999",
                            "0.03:0.01", "0.03:0.01:2:2", "0.03:0:2", "0.01:0.03:2", "0.03:0.01:1",
                            "0.03:0.01:0.5", "0.03:x:2", "1:1e-300:1.0000001"}) {
        const DtParse p = parse_dt_list(bad);
        EXPECT_FALSE(p.error.empty()) << "'" << bad << "' was accepted";
        EXPECT_TRUE(p.dts.empty()) << bad;
    }
}

TEST(SweepDtList, DefaultIsCapped) {
    const auto dts = default_sweep_dts(0.03);
    ASSERT_EQ(dts.size(), 8u);  // 0.03 .. 0.03/2^7
    EXPECT_EQ(dts.front(), 0.03);
    EXPECT_EQ(dts.back(), 0.03 / 128);
    // Small dt: stops at 1e-5.
    const auto small = default_sweep_dts(1e-4);
    EXPECT_EQ(small.size(), 4u);  // 1e-4, 5e-5, 2.5e-5, 1.25e-5
    EXPECT_GE(small.back(), 1e-5);
    EXPECT_EQ(default_sweep_dts(1e-6), std::vector<double>{1e-6});
}

TEST(SweepOrder, ReferenceConvergesAtFirstOrder) {
    const Scenario s = load_scenario(kScenarios + "/seed-3d.toml");
    auto all = built_simulators();
    SweepRequest request;
    request.simulators = {find_simulator(all, "reference")};
    request.dts = parse_dt_list("0.03:0.0009375:2").dts;  // 0.03 .. 0.03/32
    ASSERT_EQ(request.dts.size(), 6u);
    request.repeat = 1;
    const SweepResult r = run_sweep(s, request);
    ASSERT_EQ(r.rows.size(), 6u);
    for (const SweepRow& row : r.rows) {
        EXPECT_EQ(row.status, RunStatus::ok) << row.reason;
        ASSERT_TRUE(row.error && row.ns_per_step && row.sec_per_sim_sec && row.steps);
        EXPECT_GT(*row.error, 0);
    }
    EXPECT_LT(*r.rows.back().error, *r.rows.front().error);
    ASSERT_EQ(r.orders.size(), 1u);
    ASSERT_TRUE(r.orders[0].order);
    EXPECT_EQ(r.orders[0].points, 6);
    EXPECT_NEAR(*r.orders[0].order, 1.0, 0.2);
}

TEST(SweepOrder, FitsAKnownSlope) {
    std::vector<SweepRow> rows;
    for (double dt : {0.1, 0.05, 0.025}) {
        SweepRow row;
        row.engine = "x";
        row.dt = dt;
        row.error = 3 * dt * dt;
        rows.push_back(row);
    }
    rows[0].engine = "x";
    SweepRow failed;
    failed.engine = "x";
    failed.dt = 0.01;
    failed.status = RunStatus::failed;
    rows.push_back(failed);
    const SweepOrder o = fit_order(rows, "x");
    EXPECT_EQ(o.points, 3);
    ASSERT_TRUE(o.order);
    EXPECT_NEAR(*o.order, 2.0, 1e-12);
    EXPECT_FALSE(fit_order(rows, "y").order);
}

// An order is printed with why it is not the law's: round-off has none,
// and friction mode converges to Coulomb friction.
TEST(SweepOrder, CaveatsNameRoundOffAndFrictionMode) {
    Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-2d.toml");
    SweepResult r;
    for (const double dt : {0.03, 0.01, 0.003}) {
        for (const char* engine : {"floor", "bullet", "law"}) {
            SweepRow row;
            row.engine = engine;
            row.dt = dt;
            row.error = std::string(engine) == "floor" ? 1e-13 * dt : dt;
            r.rows.push_back(row);
        }
    }
    for (const char* engine : {"floor", "bullet", "law"}) r.orders.push_back(fit_order(r.rows, engine));
    EXPECT_NE(order_caveat(r.orders[0], r, s).find("round-off"), std::string::npos);
    EXPECT_NE(order_caveat(r.orders[1], r, s).find("Coulomb"), std::string::npos);  // seed-2d's bullet has a mu
    EXPECT_EQ(order_caveat(r.orders[2], r, s), "");
    s.engines["bullet"].tangential_model = TangentialModel::per_contact;
    EXPECT_EQ(order_caveat(r.orders[1], r, s), "");
}

TEST(SweepPareto, KeepsTheRowsNoOtherBeatsOnBothCostAndError) {
    // (cost, error): (1, 10) front; (2, 5) front; (3, 5) dominated by (2, 5);
    // (4, 1) front; (0.5, 20) front; a failed row and a zero-error row are never on it.
    std::vector<SweepRow> rows;
    const double points[][2] = {{1, 10}, {2, 5}, {3, 5}, {4, 1}, {0.5, 20}, {0.1, 0.1}, {0.1, 0}};
    for (const auto& p : points) {
        SweepRow row;
        row.engine = "x";
        row.sec_per_sim_sec = p[0];
        row.error = p[1];
        rows.push_back(row);
    }
    rows[5].status = RunStatus::failed;
    EXPECT_EQ(pareto_front(rows), (std::vector<bool>{true, true, false, true, true, false, false}));
}

// The sweep times the reference on its unrecorded path (free flight, the
// periodic rest counted): it must be the same run, ending in the same bits.
TEST(SweepTiming, ReferencesUnrecordedRunEndsInTheSameState) {
    const auto reference = make_reference_simulator();
    for (const char* name : {"seed-2d.toml", "seed-3d.toml"}) {
        Scenario s = load_scenario(kScenarios + "/" + name);
        s.duration = 40000;  // through the periodic rest (~1.1e6 steps in)
        const SimulatorSummary recorded = record_run(*reference, s);
        const UnrecordedRun unrecorded = reference->run_unrecorded(s);
        EXPECT_EQ(unrecorded.status, RunStatus::ok);
        EXPECT_EQ(unrecorded.steps, recorded.steps) << name;
        EXPECT_EQ(unrecorded.final_state.t, recorded.final_state.t) << name;
        EXPECT_EQ(unrecorded.final_state.p, recorded.final_state.p) << name;
        EXPECT_EQ(unrecorded.final_state.v, recorded.final_state.v) << name;
    }
}

TEST(SweepParallel, ResultsDoNotDependOnJobs) {
    const Scenario s = load_scenario(kScenarios + "/seed-2d.toml");
    auto all = built_simulators();
    SweepRequest request;
    for (const char* name : {"reference", "bullet", "ode", "box2d"})
        if (const Simulator* sim = find_simulator(all, name)) request.simulators.push_back(sim);
    request.dts = {0.03, 0.015, 0.0075};
    request.repeat = 1;
    request.jobs = 1;
    const SweepResult one = run_sweep(s, request);
    request.jobs = 2;
    const SweepResult two = run_sweep(s, request);
    ASSERT_EQ(one.rows.size(), request.simulators.size() * 3);
    ASSERT_EQ(one.rows.size(), two.rows.size());
    for (std::size_t i = 0; i < one.rows.size(); ++i) {
        const SweepRow &a = one.rows[i], &b = two.rows[i];
        EXPECT_EQ(a.engine, b.engine);
        EXPECT_EQ(a.dt, b.dt);
        EXPECT_EQ(a.status, b.status) << a.engine << " " << a.dt;
        EXPECT_EQ(a.error, b.error) << a.engine << " " << a.dt;
        EXPECT_EQ(a.bounce_error, b.bounce_error) << a.engine << " " << a.dt;
        EXPECT_EQ(a.steps, b.steps) << a.engine << " " << a.dt;
    }
    for (std::size_t e = 0; e < one.orders.size(); ++e) EXPECT_EQ(one.orders[e].order, two.orders[e].order);
    // Rows are engine-major in the request's order, dt in the request's order.
    EXPECT_EQ(one.rows[0].engine, "reference");
    EXPECT_EQ(one.rows[2].dt, 0.0075);
}

TEST(SweepRows, SkippedPairIsARowWithItsReason) {
    auto all = built_simulators();
    const Simulator* box2d = find_simulator(all, "box2d");
    if (!box2d) GTEST_SKIP() << "box2d not built";
    const Scenario s = load_scenario(kScenarios + "/seed-3d.toml");
    SweepRequest request;
    request.simulators = {find_simulator(all, "reference"), box2d};
    request.dts = {0.03, 0.015};
    request.repeat = 1;
    const SweepResult r = run_sweep(s, request);
    ASSERT_EQ(r.rows.size(), 4u);
    for (std::size_t i = 2; i < 4; ++i) {
        EXPECT_EQ(r.rows[i].engine, "box2d");
        EXPECT_EQ(r.rows[i].status, RunStatus::skipped);
        EXPECT_FALSE(r.rows[i].reason.empty());
        EXPECT_FALSE(r.rows[i].error);
        EXPECT_FALSE(r.rows[i].ns_per_step);
    }
    EXPECT_FALSE(r.orders[1].order);
    // The CSV keeps the row with empty values; the JSON gives the reason.
    const std::string csv = sweep_csv(r);
    EXPECT_NE(csv.find("box2d,0.029999999999999999,skipped,,,,,,\n"), std::string::npos) << csv;
    const auto json = sweep_json(s, r, nlohmann::json::object());
    EXPECT_EQ(json["rows"][2]["status"], "skipped");
    EXPECT_FALSE(json["rows"][2]["reason"].get<std::string>().empty());
    EXPECT_TRUE(json["rows"][2]["error"].is_null());
}

// The reference, faulty at some time steps: `fault(dt)` runs first, and may
// throw, abort (in its worker process) or never return.
class Faulty final : public Simulator {
public:
    Faulty(const Simulator& inner, std::string_view name, std::function<void(double)> fault)
        : inner_(inner), name_(name), fault_(std::move(fault)) {}
    std::string_view name() const override { return name_; }
    std::string_view description() const override { return "the reference, faulty at some time steps"; }
    RunOutcome run(const Scenario& s, RunSink& sink) const override {
        fault_(s.dt);
        return inner_.run(s, sink);
    }

private:
    const Simulator& inner_;
    std::string_view name_;
    std::function<void(double)> fault_;
};

TEST(SweepRows, FailedPairIsARowWithItsReason) {
    auto all = built_simulators();
    const Faulty fragile(*find_simulator(all, "reference"), "fragile", [](double dt) {
        if (dt < 0.02) throw std::runtime_error("too fine");
    });
    const Scenario s = load_scenario(kScenarios + "/seed-2d.toml");
    SweepRequest request;
    request.simulators = {&fragile};
    request.dts = {0.03, 0.015};
    request.repeat = 1;
    const SweepResult r = run_sweep(s, request);
    ASSERT_EQ(r.rows.size(), 2u);
    EXPECT_EQ(r.rows[0].status, RunStatus::ok);
    EXPECT_EQ(r.rows[1].status, RunStatus::failed);
    EXPECT_NE(r.rows[1].reason.find("too fine"), std::string::npos) << r.rows[1].reason;
    EXPECT_FALSE(r.rows[1].error);
    EXPECT_EQ(r.orders[0].points, 1);
    EXPECT_FALSE(r.orders[0].order);
}

TEST(SweepRows, CrashedAndHungPairsCostTheirOwnRowsOnly) {
    auto all = built_simulators();
    const Faulty doomed(*find_simulator(all, "reference"), "doomed", [](double dt) {
        if (dt == 0.015) std::abort();
        if (dt == 0.0075)
            for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));  // a step that never returns
    });
    const Scenario s = load_scenario(kScenarios + "/seed-2d.toml");
    SweepRequest request;
    request.simulators = {&doomed, find_simulator(all, "reference")};
    request.dts = {0.03, 0.015, 0.0075};
    request.repeat = 1;
    request.jobs = 2;
    request.budget_seconds = 0.5;
    const SweepResult r = run_sweep(s, request);
    ASSERT_EQ(r.rows.size(), 6u);
    EXPECT_EQ(r.rows[0].status, RunStatus::ok);
    EXPECT_EQ(r.rows[1].status, RunStatus::failed);
    EXPECT_EQ(r.rows[1].reason.rfind("crashed: signal 6", 0), 0u) << r.rows[1].reason;
    EXPECT_EQ(r.rows[2].status, RunStatus::failed);
    EXPECT_EQ(r.rows[2].reason.rfind("hung: no result after", 0), 0u) << r.rows[2].reason;
    EXPECT_EQ(r.rows[2].engine, "doomed");
    EXPECT_EQ(r.rows[2].dt, 0.0075);
    for (std::size_t i = 3; i < 6; ++i) EXPECT_EQ(r.rows[i].status, RunStatus::ok) << r.rows[i].reason;
    // The doomed engine's good row is the reference's, bit for bit.
    EXPECT_EQ(r.rows[0].error, r.rows[3].error);
}

fs::path fresh_dir(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("bouncecheck-test-" + name + "-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    return dir;
}

TEST(SweepCli, WritesCsvAndJson) {
    auto all = built_simulators();
    if (!find_simulator(all, "ode")) GTEST_SKIP() << "ode not built";
    const fs::path out = fresh_dir("sweep");
    const test::CliResult r = test::bouncecheck("sweep " + kScenarios +
                                    "/seed-2d.toml --engines reference,ode --dt 0.03,0.015 --repeat 1 --out " +
                                    out.string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("observed order"), std::string::npos) << r.output;
    std::ifstream csv(out / "sweep.csv");
    std::string line;
    ASSERT_TRUE(std::getline(csv, line));
    EXPECT_EQ(line, "engine,dt,status,error,bounce_error,ns_per_step,sec_per_sim_sec,steps,outside_step_seconds");
    int rows = 0;
    while (std::getline(csv, line)) {
        EXPECT_NE(line.find(",ok,"), std::string::npos) << line;
        ++rows;
    }
    EXPECT_EQ(rows, 4);
    std::ifstream json_in(out / "sweep.json");
    const auto json = nlohmann::json::parse(json_in);
    EXPECT_EQ(json["schema"], kSweepSchema);
    EXPECT_EQ(json["rows"].size(), 4u);
    EXPECT_EQ(json["orders"].size(), 2u);
    EXPECT_EQ(json["parameters"]["repeat"], 1);
    for (const auto& row : json["rows"]) EXPECT_TRUE(row["pareto"].is_boolean());
    // The plot page, self-contained (its rendering: tests/browser/check_pages.sh).
    const std::string html = test::slurp(out / "sweep.html");
    EXPECT_NE(html.find("\"kind\":\"sweep\""), std::string::npos);
    EXPECT_EQ(html.find("src=\"http"), std::string::npos);
    fs::remove_all(out);
}

TEST(SweepCli, BadInputExitsTwo) {
    const std::string scenario = kScenarios + "/seed-2d.toml";
    const fs::path out = fresh_dir("sweep-bad");
    for (const std::string args : {" --dt 0.03,x", " --dt 0.03:0.01", " --dt -0.01", " --dt 100", " --dt 1e-300", " --dt 1e-10",
                                   " --engines nosuch", " --engines exact", " --repeat 0"}) {
        const test::CliResult r = test::bouncecheck("sweep " + scenario + args + " --out " + out.string());
        EXPECT_EQ(r.status, 2) << args << ": " << r.output;
    }
    EXPECT_EQ(test::bouncecheck("sweep /nonexistent.toml --out " + out.string()).status, 2);
    EXPECT_FALSE(fs::exists(out / "sweep.csv"));
    fs::remove_all(out);
}

}  // namespace
