// The C++ API (api/bouncecheck.h, api/gtest.h): check_law judges a
// simulator against the law as `bouncecheck run` compares it, fails a wrong
// one with its reasons and the harness's table, and run_and_report writes
// the run's files. tests/install/consumer.sh builds examples/cmake-consumer
// against an installed prefix.
#include "api/bouncecheck.h"
#include "api/gtest.h"
#include "reference/reference_simulator.h"
#include "registry/registry.h"
#include "tests/support/test_directory.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>

namespace fs = std::filesystem;

namespace bouncecheck {
namespace {

const std::string kScenarios = BOUNCECHECK_SCENARIO_DIR;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The reference's own Euler, but with another alpha than the scenario's: a
// simulator that does not follow the law.
class WrongAlpha final : public Simulator {
public:
    explicit WrongAlpha(double alpha, std::string name = "wrong-alpha") : alpha_(alpha), name_(std::move(name)) {}
    std::string_view name() const override { return name_; }
    std::string_view description() const override { return "the reference with another alpha"; }
    RunOutcome run(const Scenario& s, RunSink& sink) const override {
        Scenario wrong = s;
        wrong.alpha = alpha_;
        return reference_->run(wrong, sink);
    }

private:
    double alpha_;
    std::string name_;
    std::unique_ptr<const Simulator> reference_ = make_reference_simulator();
};

// The seed's 2D scenario at dt = 1e-3 (the bar's step), per contact.
Scenario seed_2d_fine() {
    Scenario s = load_scenario(kScenarios + "/seed-2d-per-contact.toml");
    s.dt = 1e-3;
    return s;
}

TEST(Api, TheLawsOwnAlphaPassesAndAnotherFailsWithItsReasonsAndTheTable) {
    const Scenario s = seed_2d_fine();
    // The document's Euler with the law's alpha, under another name: it is
    // the reference, so it follows the law to the reference's own error.
    const LawCheck right = check_law(s, WrongAlpha(s.alpha, "euler"));
    EXPECT_TRUE(right.passed) << ::testing::PrintToString(right.failures) << "\n" << right.table;
    ASSERT_TRUE(right.first_contact_t && right.exact_first_contact_t);
    EXPECT_EQ(right.apex_rel.size(), 3u);
    ASSERT_TRUE(right.alpha_measured);
    EXPECT_NEAR(*right.alpha_measured, 0.8, 1e-9);  // the reference's contacts measure alpha exactly

    const LawCheck wrong = check_law(s, WrongAlpha(0.7));
    EXPECT_FALSE(wrong.passed);
    std::string failures;
    for (const std::string& f : wrong.failures) failures += f + "\n";
    EXPECT_TRUE(contains(failures, "apex 1 after the start:")) << failures;
    EXPECT_TRUE(contains(failures, "damping: ")) << failures;
    EXPECT_TRUE(contains(wrong.table, "wrong-alpha")) << wrong.table;
    EXPECT_TRUE(contains(wrong.table, "apex err")) << wrong.table;

    // The GoogleTest helper: the same verdict, and a message with the reasons and the table.
    EXPECT_FOLLOWS_THE_LAW(s, WrongAlpha(s.alpha, "euler"));
    const ::testing::AssertionResult helper = testing::FollowsTheLaw(s, WrongAlpha(0.7));
    EXPECT_FALSE(helper);
    EXPECT_TRUE(contains(helper.message(), "wrong-alpha does not follow the law on seed-2d-per-contact:"))
        << helper.message();
    EXPECT_TRUE(contains(helper.message(), "apex err")) << helper.message();
}

TEST(Api, ToleranceAndNameAreTheCallers) {
    const Scenario s = seed_2d_fine();
    LawTolerances loose;
    loose.apex_rel = 1;
    loose.first_contact_rel = 1;
    loose.damping_verdict = false;
    EXPECT_TRUE(check_law(s, WrongAlpha(0.7), loose).passed);
    const LawCheck taken = check_law(s, WrongAlpha(0.8, "exact"));
    EXPECT_FALSE(taken.passed);
    ASSERT_EQ(taken.failures.size(), 1u);
    EXPECT_TRUE(contains(taken.failures[0], "'exact' is a baseline's name")) << taken.failures[0];
    EXPECT_FALSE(check_law(s, WrongAlpha(0.8, "a b/c")).passed);  // not a valid name
    // More apexes than the scenario's bounce_count (5, the start included) are compared when asked.
    LawTolerances many;
    many.apexes = 6;
    const LawCheck six = check_law(s, WrongAlpha(0.8, "euler"), many);
    EXPECT_EQ(six.apex_rel.size(), 6u);
    EXPECT_TRUE(six.passed) << ::testing::PrintToString(six.failures);
}

// The bar the compiled engines meet in per-contact mode at dt = 1e-3 holds
// for every 2D engine this build has, through the API.
TEST(Api, EveryBuilt2dEngineMeetsTheBarThroughTheApi) {
    const Scenario s = seed_2d_fine();
    int judged = 0;
    for (const auto& sim : built_simulators()) {
        if (sim->name() == "reference" || sim->name() == "exact" || sim->cannot_run(s)) continue;
        EXPECT_FOLLOWS_THE_LAW(s, *sim);
        ++judged;
    }
    if (judged == 0) GTEST_SKIP() << "no engine built";
}

class ApiReport : public test::TestDirectory {};

TEST_F(ApiReport, RunAndReportWritesWhatRunWrites) {
    const Scenario s = seed_2d_fine();
    const WrongAlpha wrong(0.7);
    std::string terminal;
    const int status = run_and_report({s}, {&wrong}, dir_ / "out", &terminal);
    EXPECT_EQ(status, 1) << terminal;  // the seed's thresholds hold wrong-alpha to the reference: exceeded
    EXPECT_TRUE(contains(terminal, "wrong-alpha on seed-2d-per-contact")) << terminal;
    for (const char* file : {"report.json", "report.md", "junit.xml", "bounces.csv", "report.html",
                             "bouncecheck-manifest.tsv"})
        EXPECT_TRUE(fs::exists(dir_ / "out" / file)) << file;
    EXPECT_TRUE(contains(terminal, "wrong-alpha")) << terminal;
    EXPECT_TRUE(contains(terminal, "verdict: ")) << terminal;
    std::string why;
    EXPECT_EQ(run_and_report({s}, {&wrong}, dir_ / "out" / "report.json" / "x", &why), 2);  // not a folder
    EXPECT_TRUE(contains(why, "cannot create")) << why;
    EXPECT_EQ(run_and_report({s}, {&wrong, &wrong}, dir_ / "out", &why), 2);
    EXPECT_TRUE(contains(why, "two simulators are named 'wrong-alpha'")) << why;
}

}  // namespace
}  // namespace bouncecheck
