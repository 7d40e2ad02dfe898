// `bouncecheck table`: every simulator of a run side by side
// (reports/engine_table.h), and docs/engines.md's generated copy of it.
#include "reports/engine_table.h"
#include "scenarios/loader.h"
#include "tests/support/cli.h"
#include "tests/support/test_directory.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace bouncecheck {
namespace {

using json = nlohmann::json;
using test::bouncecheck;
using test::CliResult;
using test::slurp;

// The cells of the table's row for `simulator` on `scenario`, or none.
std::vector<std::string> row_of(const std::string& table, const std::string& scenario, const std::string& simulator) {
    std::istringstream lines(table);
    for (std::string line; std::getline(lines, line);) {
        std::vector<std::string> cells;
        std::istringstream parts(line);
        for (std::string part; std::getline(parts, part, '|');) {
            const auto first = part.find_first_not_of(' '), last = part.find_last_not_of(' ');
            cells.push_back(first == std::string::npos ? "" : part.substr(first, last - first + 1));
        }
        if (cells.size() > 2 && cells[1] == scenario && cells[2] == simulator) return {cells.begin() + 1, cells.end()};
    }
    return {};
}

// One simulator's part of a report, as the run writes it.
json simulator(const std::string& name) {
    return {{"simulator", name},
            {"status", "ok"},
            {"ns_per_step", 1234.4},
            {"rest_time", 12.5},
            {"settings",
             {{{"key", "engine"}, {"value", "Engine 1.2 (npm engine 1.2.0)"}, {"why", ""}},
              {{"key", "precision"}, {"value", "double (sizeof(btScalar) = 8)"}, {"why", ""}}}},
            {"first_floor_contacts", {{{"t", 1.01}, {"restitution", 0.8}}}},
            {"comparison",
             {{"vs_exact",
               {{"bounces",
                 {{{"index", 0}, {"contact_t", 1.01}, {"baseline_contact_t", 1.0}, {"rel_diff", 0.0}},
                  {{"index", 1}, {"rel_diff", -0.02}},
                  {{"index", 2}, {"rel_diff", 0.01}},
                  {{"index", 3}, {"rel_diff", 0.005}},
                  {{"index", 4}, {"rel_diff", 0.5}}}}}},
              {"damping", {{"contacts", 3}, {"normal_mean", 0.79}, {"tangential_contacts", 0}}}}}};
}

// exact's part of a report: its first floor contact at 1 s, its first apex at `first_apex_t`.
json exact_of(double first_apex_t = 0) {
    return {{"simulator", "exact"},
            {"status", "ok"},
            {"apexes", {{{"t", first_apex_t}, {"height", 1.0}}}},
            {"first_floor_contacts", {{{"t", 1.0}, {"restitution", 0.8}}}}};
}

json report_of(std::vector<json> simulators) {
    return {{"schema", "bouncecheck-report/1"},
            {"scenarios", {{{"scenario", {{"name", "s"}}}, {"simulators", std::move(simulators)}}}}};
}

TEST(EngineTable, EachRowReadsItsSimulatorsFiguresAgainstExact) {
    const std::string table = engine_table_markdown(report_of({exact_of(), simulator("a")}));
    const auto cells = row_of(table, "s", "a");
    ASSERT_EQ(cells.size(), 10u) << table;
    EXPECT_EQ(cells[2], "Engine 1.2 (npm engine 1.2.0)");
    EXPECT_EQ(cells[3], "f64");         // "double (...)", in the Node engines' words
    EXPECT_EQ(cells[4], "1.000%");      // the first floor contacts: |1.01 - 1| / 1
    EXPECT_EQ(cells[5], "2.000%");      // the worst of apexes 1-3: apex 4 is not counted
    EXPECT_EQ(cells[6], "0.7900");      // alpha measured
    EXPECT_EQ(cells[7], "-");           // no tangential contact measured: no beta
    EXPECT_EQ(cells[8], "12.500");
    EXPECT_EQ(cells[9], "1234");
}

TEST(EngineTable, TheApexesComparedAreTheThreeAfterTheStartAsTheLawsCheckTakesThem) {
    json a = simulator("a");
    a["comparison"]["vs_exact"]["bounces"][0]["rel_diff"] = 0.04;
    json exact = exact_of();
    // The start is an apex (exact's first at t = 0): apexes 1-3 are compared.
    EXPECT_EQ(row_of(engine_table_markdown(report_of({exact, a})), "s", "a").at(5), "2.000%");
    // The ball starts moving up: its first apex is a bounce's, compared too.
    exact["apexes"][0]["t"] = 0.4;
    EXPECT_EQ(row_of(engine_table_markdown(report_of({exact, a})), "s", "a").at(5), "4.000%");
}

TEST(EngineTable, WhatARowLacksOrHoldsAsAnotherTypeShowsAsADash) {
    json odd = simulator("odd|name");
    odd["ns_per_step"] = "fast";
    odd["rest_time"] = nullptr;  // never at rest
    odd["settings"] = 7;
    odd["first_floor_contacts"][0]["t"] = json::array();
    odd["comparison"]["damping"] = "none";
    json failed = {{"simulator", "b"}, {"status", "failed"}};
    json skipped = {{"simulator", "c"}, {"status", "skipped"}};
    const std::string table =
        engine_table_markdown(report_of({exact_of(), odd, failed, skipped, json("not an object")}));
    const auto cells = row_of(table, "s", "odd name");  // a pipe cannot end a cell early
    ASSERT_EQ(cells.size(), 10u) << table;
    EXPECT_EQ(cells[2], "-");
    EXPECT_EQ(cells[4], "-");
    EXPECT_EQ(cells[5], "2.000%");
    EXPECT_EQ(cells[6], "-");
    EXPECT_EQ(cells[8], "none");
    EXPECT_EQ(cells[9], "-");
    EXPECT_EQ(row_of(table, "s", "b").at(4), "failed");
    EXPECT_TRUE(row_of(table, "s", "c").empty());  // a scenario of the other dimension: no row
    EXPECT_EQ(engine_table_markdown(json::array()).find("| s |"), std::string::npos);
}

class EngineTableCli : public test::TestDirectory {};

TEST_F(EngineTableCli, TableOfARunShowsExactAgainstItselfAndRefusesWhatIsNotAReport) {
    const std::string out = (dir_ / "run").string();
    const CliResult run = bouncecheck(fmt::format("run {}/seed-3d.toml --engines reference,exact --out {}",
                                                  BOUNCECHECK_SCENARIO_DIR, out));
    ASSERT_TRUE(run.status == 0 || run.status == 1) << run.output;
    const CliResult table = bouncecheck("table " + out);
    ASSERT_EQ(table.status, 0) << table.output;
    const auto exact = row_of(table.output, "seed-3d", "exact");
    ASSERT_EQ(exact.size(), 10u) << table.output;
    EXPECT_EQ(exact[4], "0.000%");
    EXPECT_EQ(exact[5], "0.000%");
    EXPECT_EQ(exact[6], "0.8000");  // the law's alpha, measured off exact's own impacts
    EXPECT_EQ(row_of(table.output, "seed-3d", "reference").size(), 10u) << table.output;
    // --out writes the same table.
    ASSERT_EQ(bouncecheck("table " + out + " --out " + (dir_ / "t.md").string()).status, 0);
    EXPECT_EQ(slurp(dir_ / "t.md"), table.output);

    const fs::path bad = write_file("report.json", "{\"schema\": \"bouncecheck-report/1\", ");
    const CliResult refused = bouncecheck("table " + bad.string());
    EXPECT_EQ(refused.status, 2);
    EXPECT_NE(refused.output.find(bad.string() + ": not JSON"), std::string::npos) << refused.output;
}

// docs/engines.md carries the table scripts/engine-table.sh generates: every
// simulator bouncecheck can be built with has its rows there, so that an
// engine added without regenerating the table is noticed.
TEST(EngineTableDocs, TheGeneratedTableCoversEverySimulator) {
    const std::string page = slurp(fs::path(BOUNCECHECK_SCENARIO_DIR).parent_path() / "docs" / "engines.md");
    const std::string begin = "<!-- engine-table: generated by scripts/engine-table.sh; do not edit -->";
    const auto from = page.find(begin), to = page.find("<!-- engine-table: end -->");
    ASSERT_NE(from, std::string::npos);
    ASSERT_NE(to, std::string::npos);
    const std::string table = page.substr(from + begin.size() + 1, to - from - begin.size() - 1);
    // The header as this build renders it: a column changed since is noticed.
    const std::string header = engine_table_markdown(json::object());
    EXPECT_EQ(table.substr(0, header.size()), header) << "run scripts/engine-table.sh";
    // Every row a run's: no simulator failed in the run the page shows.
    std::istringstream rows(table);
    for (std::string line; std::getline(rows, line);)
        for (const char* status : {"| failed |", "| crashed |", "| hung |", "| gave up |"})
            EXPECT_EQ(line.find(status), std::string::npos) << line;
    for (const std::string_view name : kBuiltInSimulators)
        EXPECT_FALSE(row_of(table, "seed-3d", std::string(name)).empty() &&
                     row_of(table, "seed-2d", std::string(name)).empty())
            << name << " has no row: run scripts/engine-table.sh";
}

}  // namespace
}  // namespace bouncecheck
