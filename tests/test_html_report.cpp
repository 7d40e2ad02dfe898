// report.html's data: the decimated traces keep every bounce, the distance
// series keep every spike, exact's path has its contacts at their instants,
// and the page is self-contained and parses back to the run's numbers.
// (Rendering in a real browser: tests/browser/check_pages.sh.)
#include "commands/run/run_pipeline.h"
#include "exact/exact_model.h"
#include "metrics/summary.h"
#include "reference/reference_simulator.h"
#include "reports/plot_data.h"
#include "reports/run_report.h"
#include "reports/web_assets.h"
#include "scenarios/loader.h"
#include "simulators/document_clock.h"
#include "simulators/simulator.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <unistd.h>
#include <string>

namespace bouncecheck {
namespace {

Scenario seed(const char* name) { return load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/" + name); }

TEST(TraceDecimator, KeepsEveryVerticalReversalWithinTheBudget) {
    const Scenario s = seed("seed-3d.toml");
    StateVector all;
    TraceDecimator decimator(expected_states(s), s.dim, 100);
    record_run(*make_reference_simulator(), s, &all);
    for (const State& st : all.states) decimator.write(st);
    const PlotTrace trace = decimator.finish();

    // Fewer points than states, but every floor contact (vertical velocity
    // turning from down to up) is in the trace at its sample's time.
    ASSERT_GT(all.states.size(), 1000u);
    EXPECT_LT(trace.size(), all.states.size() / 2);
    int reversals = 0;
    for (std::size_t i = 1; i < all.states.size(); ++i) {
        if (!(all.states[i - 1].v.z() < 0 && all.states[i].v.z() > 0)) continue;
        ++reversals;
        const auto it = std::find(trace.t.begin(), trace.t.end(), all.states[i].t);
        ASSERT_NE(it, trace.t.end()) << "contact at t = " << all.states[i].t << " lost";
        EXPECT_EQ(trace.p[static_cast<std::size_t>(it - trace.t.begin())], all.states[i].p);
    }
    EXPECT_GE(reversals, 10);
    EXPECT_EQ(trace.t.front(), 0.0);
    EXPECT_EQ(trace.t.back(), all.states.back().t);
    EXPECT_TRUE(std::is_sorted(trace.t.begin(), trace.t.end()));
}

TEST(TraceDecimator, JitterDoesNotGrowTheTraceWithoutBound) {
    // A velocity that reverses every step for a million steps.
    TraceDecimator decimator(1'000'000, 3, 600);
    for (int i = 0; i < 1'000'000; ++i) {
        State st;
        st.t = i * 1e-3;
        st.v = Vec3((i % 2) ? 1.0 : -1.0, 0, 0);
        decimator.write(st);
    }
    const PlotTrace trace = decimator.finish();
    EXPECT_LE(trace.size(), 600u + kPlotTurningPoints + 2);
}

// The reversal screen reads signs and zeros from the bits: a subnormal
// velocity that changes sign or becomes zero is a turning point; one whose
// product with the next underflows to zero without a sign change is not,
// nor is a component that was already zero.
TEST(TraceDecimator, KeepsReversalsOfSubnormalVelocitiesAndNoOtherTinyChange) {
    const double tiny = 1e-310, underflowing = 1e-200;  // tiny subnormal; underflowing^2 rounds to 0
    const Vec3 velocities[] = {{tiny, 1, 0},  {2 * tiny, 1, 0}, {-tiny, 1, 0},     {-0x1p-1074, 1, 0},
                               {0.0, 1, 0},   {-0.0, 1, 0},     {underflowing, 1, 0}, {underflowing, 1, 0},
                               {2 * underflowing, 1, 0}};
    TraceDecimator decimator(1'000'000, 3, 600);  // a stride far beyond these states
    for (std::size_t i = 0; i < std::size(velocities); ++i) {
        State st;
        st.t = static_cast<double>(i);
        st.v = velocities[i];
        decimator.write(st);
    }
    const PlotTrace trace = decimator.finish();
    // 0: the first state; 2 and 4 turn (sign, then zero), each with the
    // state before it; 8: the last.
    EXPECT_EQ(trace.t, (std::vector<double>{0, 1, 2, 3, 4, 8}));
}

// In 2D only the scene's two axes turn: a reversal on the third, which
// the page does not draw, keeps no point; in 3D the same stream keeps it.
TEST(TraceDecimator, InTwoDimensionsOnlyTheScenesAxesTurn) {
    for (const int axes : {2, 3}) {
        TraceDecimator decimator(1'000'000, axes, 600);  // a stride far beyond these states
        for (int i = 0; i < 6; ++i) {
            State st;
            st.t = i;
            st.v = Vec3(1, 1, i == 3 ? -1e-17 : 1e-17);  // the third axis reverses at 3 and back at 4
            decimator.write(st);
        }
        const std::vector<double> kept = decimator.finish().t;
        if (axes == 2) EXPECT_EQ(kept, (std::vector<double>{0, 5}));
        else EXPECT_EQ(kept, (std::vector<double>{0, 2, 3, 4, 5}));
    }
}

TEST(WindowMaxSeries, KeepsTheLargestValueOfEachWindowWithItsTime) {
    WindowMaxSeries series(4);
    const double values[] = {1, 5, 2, 3, /**/ 0.5, 0.1, 9, 0.2, /**/ 7};
    for (int i = 0; i < 9; ++i) series.add(i, values[i]);
    EXPECT_EQ(series.times(), (std::vector<double>{1, 6, 8}));
    EXPECT_EQ(series.values(), (std::vector<double>{5, 9, 7}));
}

TEST(ExactPlotTrace, HasEveryContactAtItsInstantAndPosition) {
    const Scenario s = seed("seed-2d.toml");
    const ExactModel exact(s);
    const PlotTrace trace = exact_plot_trace(exact, s);
    ASSERT_FALSE(exact.contacts().empty());
    for (const WallContact& c : exact.contacts()) {
        const auto it = std::find(trace.t.begin(), trace.t.end(), c.t);
        ASSERT_NE(it, trace.t.end()) << "contact at t = " << c.t;
        EXPECT_EQ(trace.p[static_cast<std::size_t>(it - trace.t.begin())], c.p);
    }
    EXPECT_TRUE(std::is_sorted(trace.t.begin(), trace.t.end()));
}

// The samples are the document clock's every stride-th and its last, with
// the events between them, as a walk over every sample keeps them (the
// trace jumps from kept sample to kept sample).
TEST(ExactPlotTrace, KeepsTheClocksSamplesAsAWalkOverEverySample) {
    for (const char* file : {"seed-2d.toml", "seed-3d.toml"}) {
        Scenario s = seed(file);
        s.duration = 4321.5;
        const ExactModel exact(s);
        const PlotTrace trace = exact_plot_trace(exact, s, 97);
        const std::int64_t stride = plot_stride(expected_states(s), 97);
        std::vector<double> kept;
        DocumentClock clock(s.dt, s.duration);
        for (std::int64_t n = 0;; ++n, clock.advance()) {
            if (n % stride == 0 || !clock.running()) kept.push_back(clock.t());
            if (!clock.running()) break;
        }
        // The kept samples in order, and nothing else but events between them.
        const auto& contacts = exact.contacts();
        const auto& apexes = exact.apexes();
        std::size_t next = 0;
        for (const double t : trace.t) {
            if (next < kept.size() && t == kept[next]) {
                ++next;
                continue;
            }
            const bool event = std::any_of(contacts.begin(), contacts.end(), [&](const auto& c) { return c.t == t; }) ||
                               std::any_of(apexes.begin(), apexes.end(), [&](const auto& a) { return a.t == t; });
            EXPECT_TRUE(event) << file << ": t = " << t;
        }
        EXPECT_EQ(next, kept.size()) << file;
        EXPECT_GT(kept.size(), 90u);
    }
}

// The data island of a page, parsed back.
nlohmann::json page_data(const std::string& page) {
    const std::string open = "<script id=\"bouncecheck-data\" type=\"application/json\">";
    const auto begin = page.find(open);
    EXPECT_NE(begin, std::string::npos);
    const auto end = page.find("</script>", begin);
    return nlohmann::json::parse(page.substr(begin + open.size(), end - begin - open.size()));
}

TEST(HtmlReport, IsSelfContainedAndCarriesTheRunsNumbers) {
    Scenario s = seed("seed-2d.toml");
    s.name = "a </script><script>alert(1)</script> name";  // must not end the data island
    ScenarioRun run = run_scenario(s, RunRequest{{make_reference_simulator().get()}, {}, false, {}, true});
    RunReport report;
    report.scenarios.push_back(run);
    const std::string page = to_html(report).text();

    EXPECT_NE(page.find(plotly_js()), std::string::npos);
    EXPECT_EQ(plotly_js().find("</script"), std::string_view::npos) << "the library would close its element";
    EXPECT_GT(plotly_js().size(), 1'000'000u);
    // Nothing is fetched: no external script, style or link.
    EXPECT_EQ(page.find("src=\"http"), std::string::npos);
    EXPECT_EQ(page.find("<link"), std::string::npos);

    const nlohmann::json data = page_data(page);
    EXPECT_EQ(data["kind"], "run");
    EXPECT_EQ(data["report"]["scenarios"][0]["scenario"]["name"], s.name);
    const nlohmann::json& sim = data["plots"][0]["simulators"][0];
    EXPECT_EQ(sim["name"], "reference");
    const PlotTrace& trace = run.plots[0]->path;
    ASSERT_EQ(sim["path"]["t"].size(), trace.size());
    // Seven significant digits of each coordinate.
    for (std::size_t i = 0; i < trace.size(); i += 37)
        EXPECT_NEAR(sim["path"]["y"][i].get<double>(), trace.p[i].y(), 1e-6 * std::abs(trace.p[i].y()) + 1e-300);
    EXPECT_EQ(sim["contacts"]["t"].size(), std::min<std::size_t>(run.results[0].contact_events.size(), 500));
    EXPECT_EQ(data["plots"][0]["exact_apexes"]["height"].size(), run.exact_apexes.size());
}

TEST(HtmlReport, IsWrittenOnlyWhenTheRunRecordedPlots) {
    const Scenario s = seed("seed-2d.toml");
    const auto dir = std::filesystem::temp_directory_path() / ("bouncecheck-html-" + std::to_string(::getpid()));
    for (bool plots : {false, true}) {
        std::filesystem::remove_all(dir);
        std::filesystem::create_directories(dir);
        RunReport report;
        report.scenarios.push_back(run_scenario(s, RunRequest{{make_reference_simulator().get()}, dir, false, {}, plots}));
        write_reports(report, dir);
        EXPECT_EQ(std::filesystem::exists(dir / "report.html"), plots);
    }
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace bouncecheck
