// Sharded runs (`stress --shard K/N`, `sweep --shard K/N`) and `bouncecheck
// merge`: the assignment of pairs to shards, and merged output equal to the
// unsharded run's apart from timings, end to end through the built binary.
#include "commands/shards.h"
#include "platform/cbor_check.h"
#include "platform/shard.h"
#include "tests/support/cli.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <sys/stat.h>

namespace fs = std::filesystem;
using namespace bouncecheck;
using test::slurp;

namespace {

TEST(Shard, ParsesKOverNAndRefusesEverythingElse) {
    std::string error;
    const auto s = parse_shard("3/8", error);
    ASSERT_TRUE(s);
    EXPECT_EQ(s->index, 3);
    EXPECT_EQ(s->count, 8);
    EXPECT_EQ(to_string(*s), "3/8");
    EXPECT_TRUE(parse_shard("1/1", error)->whole());
    for (const char* bad : {"0/3", "4/3", "-1/3", "1/0", "1/", "/3", "3", "1/3x", "a/b", "1/1000001", ""}) {
        error.clear();
        EXPECT_FALSE(parse_shard(bad, error)) << bad;
        EXPECT_FALSE(error.empty()) << bad;
    }
}

// Longest processing time first, worked by hand: 5, 4, 3 open the three
// shards; the second 3 joins the lightest (3), the 2s the next lightest
// (4, then 5), and the 1 the lower of two shards at 6.
TEST(Shard, AssignsCostliestFirstToTheLightestShard) {
    EXPECT_EQ(assign_shards({5, 4, 3, 3, 2, 2, 1}, 3), (std::vector<int>{1, 2, 3, 3, 2, 1, 2}));
    // Equal costs keep the pairs' order: round robin.
    EXPECT_EQ(assign_shards({1, 1, 1, 1, 1}, 2), (std::vector<int>{1, 2, 1, 2, 1}));
    // More shards than pairs: the last shards are empty.
    EXPECT_EQ(assign_shards({2, 7}, 4), (std::vector<int>{2, 1}));
}

TEST(Shard, EveryShardIsWithinOnePairOfTheMeanAndTheCostliestSpread) {
    std::mt19937_64 random(20261129);
    std::lognormal_distribution<double> cost(0.0, 2.0);  // heavy-tailed, as steps x ns per step are
    for (int count : {1, 2, 3, 4, 7, 50}) {
        std::vector<double> costs(1000);
        for (double& c : costs) c = cost(random);
        const std::vector<int> shard_of = assign_shards(costs, count);
        EXPECT_EQ(assign_shards(costs, count), shard_of) << "the same on every call";
        std::vector<double> load(count + 1, 0.0);
        for (std::size_t i = 0; i < costs.size(); ++i) {
            ASSERT_GE(shard_of[i], 1);
            ASSERT_LE(shard_of[i], count);
            load[shard_of[i]] += costs[i];
        }
        const double mean = std::accumulate(costs.begin(), costs.end(), 0.0) / count;
        const double costliest = *std::max_element(costs.begin(), costs.end());
        for (int k = 1; k <= count; ++k) EXPECT_LE(load[k], mean + costliest) << k << "/" << count;
        // The `count` costliest pairs land on `count` different shards.
        std::vector<std::size_t> order(costs.size());
        std::iota(order.begin(), order.end(), std::size_t{0});
        std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return costs[a] > costs[b]; });
        std::set<int> shards_of_costliest;
        for (int i = 0; i < count; ++i) shards_of_costliest.insert(shard_of[order[i]]);
        EXPECT_EQ(shards_of_costliest.size(), static_cast<std::size_t>(count));
    }
}

// ---------------------------------------------------------------- end to end

// stress.json or sweep.json without what differs between two runs of the
// same work: timings (and the Pareto flags sweep derives from them), the
// machine block and the output folder.
nlohmann::json without_timings(nlohmann::json j) {
    j.erase("wall_seconds");
    if (j.contains("provenance")) j["provenance"].erase("machine");
    j["parameters"].erase("out");
    if (j.contains("results"))
        for (auto& r : j["results"]) {
            r.erase("run_seconds");
            auto& invariants = r["invariants"];  // empty for a skipped or crashed run
            if (invariants.contains("time_budget")) {
                invariants["time_budget"].erase("worst");
                invariants["time_budget"].erase("first_value");
                invariants["flat_cost"].erase("worst");
            }
        }
    if (j.contains("rows") && j["rows"].is_array())
        for (auto& r : j["rows"])
            if (r.is_object())
                for (const char* key : {"ns_per_step", "sec_per_sim_sec", "min_seconds", "pareto"}) r.erase(key);
    return j;
}

// A CSV line's fields; a quoted field may hold commas ("" is a quote).
std::vector<std::string> csv_fields(const std::string& line) {
    std::vector<std::string> fields(1);
    bool quoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (c == '"' && quoted && i + 1 < line.size() && line[i + 1] == '"') {
            fields.back() += '"';
            ++i;
        } else if (c == '"') {
            quoted = !quoted;
        } else if (c == ',' && !quoted) {
            fields.emplace_back();
        } else {
            fields.back() += c;
        }
    }
    return fields;
}

// A CSV without the named columns (no field here holds a line break).
std::string without_columns(const std::string& csv, const std::set<std::string>& drop) {
    std::istringstream in(csv);
    std::string line, out;
    std::vector<bool> keep;
    while (std::getline(in, line)) {
        const std::vector<std::string> fields = csv_fields(line);
        if (keep.empty())
            for (const auto& name : fields) keep.push_back(!drop.count(name));
        EXPECT_EQ(fields.size(), keep.size()) << line;
        for (std::size_t i = 0; i < fields.size() && i < keep.size(); ++i)
            if (keep[i]) out += fields[i] + "|";
        out += "\n";
    }
    return out;
}

class Merge : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / fmt::format("bouncecheck-merge-{}-{}", ::getpid(),
                                                          ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string at(const std::string& name) const { return (dir_ / name).string(); }
    fs::path dir_;
};

const std::string kStressWork =
    "stress --only monte-carlo --monte-carlo 40 --engines reference,exact,ode,box2d --jobs 2";

TEST_F(Merge, ShardedStressEqualsTheWholeRunApartFromTimings) {
    const auto whole = test::bouncecheck(fmt::format("{} --out {}", kStressWork, at("whole")));
    ASSERT_TRUE(whole.status == 0 || whole.status == 1) << whole.output;
    std::size_t partial_results = 0;
    for (int k = 1; k <= 3; ++k) {
        const auto shard = test::bouncecheck(fmt::format("{} --shard {}/3 --out {}", kStressWork, k, at(fmt::format("s{}", k))));
        ASSERT_TRUE(shard.status == 0 || shard.status == 1) << shard.output;
        const auto partial = nlohmann::json::parse(slurp(dir_ / fmt::format("s{}", k) / "stress.json"));
        EXPECT_EQ(partial["parameters"]["shard"], fmt::format("{}/3", k));
        partial_results += partial["results"].size();
        // A shard lists the generated scenarios it ran, not the whole set.
        std::set<std::string> ran, listed;
        for (const auto& r : partial["results"]) ran.insert(r["scenario"].get<std::string>());
        for (const auto& g : partial["generated_scenarios"]) listed.insert(g["name"].get<std::string>());
        EXPECT_EQ(listed, ran);
        EXPECT_LT(listed.size(), 40u);
    }
    const auto merged = test::bouncecheck(fmt::format("merge {} {} {} {}", at("merged"), at("s3"), at("s1"), at("s2")));
    EXPECT_EQ(merged.status, whole.status) << merged.output;

    const std::string merged_text = slurp(dir_ / "merged" / "stress.json");
    const auto expected = nlohmann::json::parse(slurp(dir_ / "whole" / "stress.json"));
    const auto actual = nlohmann::json::parse(merged_text);
    // stress.json is written a result at a time, as the document's dump(2).
    EXPECT_EQ(actual.dump(2) + "\n", merged_text);
    EXPECT_EQ(partial_results, expected["results"].size()) << "each pair in exactly one shard";
    EXPECT_EQ(expected["results"].size(), 160u);
    EXPECT_EQ(without_timings(actual).dump(1), without_timings(expected).dump(1));
    EXPECT_EQ(actual["parameters"]["out"], at("merged"));
    const std::set<std::string> timings{"run_seconds", "cost_ratio"};
    EXPECT_EQ(without_columns(slurp(dir_ / "merged" / "stress.csv"), timings),
              without_columns(slurp(dir_ / "whole" / "stress.csv"), timings));
    // The failing generated scenarios, as files `run` reproduces.
    std::set<std::string> expected_files, actual_files;
    for (const auto& e : fs::directory_iterator(dir_ / "whole" / "stress-scenarios"))
        expected_files.insert(e.path().filename().string());
    for (const auto& e : fs::directory_iterator(dir_ / "merged" / "stress-scenarios"))
        actual_files.insert(e.path().filename().string());
    EXPECT_EQ(actual_files, expected_files);
    for (const auto& name : expected_files)
        EXPECT_EQ(slurp(dir_ / "merged" / "stress-scenarios" / name), slurp(dir_ / "whole" / "stress-scenarios" / name));
}

// sweep.html's data element, and the page around it.
std::pair<nlohmann::json, std::string> page_data(const std::string& page) {
    const std::string open = "<script id=\"bouncecheck-data\" type=\"application/json\">";
    const auto begin = page.find(open);
    const auto end = page.find("</script>", begin);
    if (begin == std::string::npos || end == std::string::npos) return {nullptr, page};
    return {nlohmann::json::parse(page.substr(begin + open.size(), end - begin - open.size())),
            page.substr(0, begin) + page.substr(end)};
}

TEST_F(Merge, ShardedSweepEqualsTheWholeSweepApartFromTimings) {
    const std::string work = fmt::format("sweep {}/seed-2d.toml --engines reference,ode,box2d --dt 0.02,0.01,0.005 "
                                         "--repeat 1 --jobs 2",
                                         BOUNCECHECK_SCENARIO_DIR);
    const auto whole = test::bouncecheck(fmt::format("{} --out {}", work, at("whole")));
    ASSERT_EQ(whole.status, 0) << whole.output;
    for (int k = 1; k <= 4; ++k)
        ASSERT_EQ(test::bouncecheck(fmt::format("{} --shard {}/4 --out {}", work, k, at(fmt::format("s{}", k)))).status, 0);
    const auto merged =
        test::bouncecheck(fmt::format("merge {} {} {} {} {}", at("merged"), at("s1"), at("s2"), at("s3"), at("s4")));
    ASSERT_EQ(merged.status, 0) << merged.output;

    const auto expected = nlohmann::json::parse(slurp(dir_ / "whole" / "sweep.json"));
    const auto actual = nlohmann::json::parse(slurp(dir_ / "merged" / "sweep.json"));
    EXPECT_EQ(expected["rows"].size(), 9u);
    EXPECT_EQ(without_timings(actual).dump(1), without_timings(expected).dump(1));
    EXPECT_EQ(actual["orders"], expected["orders"]) << "orders are fitted over every shard's rows";
    const std::set<std::string> timings{"ns_per_step", "sec_per_sim_sec"};
    EXPECT_EQ(without_columns(slurp(dir_ / "merged" / "sweep.csv"), timings),
              without_columns(slurp(dir_ / "whole" / "sweep.csv"), timings));
    const auto [expected_data, expected_page] = page_data(slurp(dir_ / "whole" / "sweep.html"));
    const auto [actual_data, actual_page] = page_data(slurp(dir_ / "merged" / "sweep.html"));
    ASSERT_FALSE(expected_data.is_null());
    EXPECT_EQ(actual_page, expected_page);
    EXPECT_EQ(without_timings(actual_data["sweep"].is_null() ? actual_data : actual_data["sweep"]).dump(1),
              without_timings(expected_data["sweep"].is_null() ? expected_data : expected_data["sweep"]).dump(1));
}

TEST_F(Merge, RefusesAnIncompleteMixedOrRepeatedSetOfShards) {
    const std::string work = "stress --only monte-carlo --monte-carlo 6 --engines reference,exact --jobs 1";
    for (int k = 1; k <= 3; ++k)
        ASSERT_LE(test::bouncecheck(fmt::format("{} --shard {}/3 --out {}", work, k, at(fmt::format("s{}", k)))).status, 1);
    ASSERT_LE(test::bouncecheck(fmt::format("{} --out {}", work, at("whole"))).status, 1);
    ASSERT_LE(test::bouncecheck(fmt::format("{} --seed 7 --shard 3/3 --out {}", work, at("other"))).status, 1);
    const auto refused = [&](const std::string& shards, const std::string& reason) {
        const auto r = test::bouncecheck(fmt::format("merge {} {}", at("merged"), shards));
        EXPECT_EQ(r.status, 2) << shards << "\n" << r.output;
        EXPECT_NE(r.output.find(reason), std::string::npos) << shards << "\n" << r.output;
        EXPECT_FALSE(fs::exists(dir_ / "merged" / "stress.json")) << shards;
    };
    refused(at("s1") + " " + at("s2"), "missing shard 3/3");
    refused(at("s1") + " " + at("s3"), "missing shard 2/3");
    refused(at("s1") + " " + at("s2") + " " + at("s2"), "are both shard 2/3");
    refused(at("s1") + " " + at("s2") + " " + at("other"), "its fingerprint (of the build and the inputs)");
    refused(at("s1") + " " + at("s2") + " " + at("whole"), at("whole") + ": cannot read shard.cbor");
    fs::create_directories(dir_ / "cut");
    const std::string bytes = slurp(dir_ / "s3" / "shard.cbor");
    std::ofstream(dir_ / "cut" / "shard.cbor", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
    refused(at("s1") + " " + at("s2") + " " + at("cut"), "shard.cbor: unreadable");
    // The same set merges.
    EXPECT_LE(test::bouncecheck(fmt::format("merge {} {} {} {}", at("merged"), at("s1"), at("s2"), at("s3"))).status, 1);
    EXPECT_TRUE(fs::exists(dir_ / "merged" / "stress.json"));
}

// cbor_problem, the walk that stands between a shard file and the decoder.
TEST(CborCheck, RefusesWhatTheDecoderWouldChokeOnAndPassesWhatItWrites) {
    const nlohmann::json doc = {{"a", {1, 2.5, "x", nullptr, true}},
                                {"b", nlohmann::json::binary({1, 2, 3})},
                                {"c", nlohmann::json::object()}};
    const auto cbor = nlohmann::json::to_cbor(doc);
    EXPECT_EQ(cbor_problem(std::string(cbor.begin(), cbor.end()), 4), std::nullopt);
    EXPECT_EQ(cbor_problem(std::string(cbor.begin(), cbor.end()), 1), "byte 3: nested deeper than 1 levels");
    const auto problem = [](const std::string& bytes) { return cbor_problem(bytes, 32).value_or("none"); };
    EXPECT_EQ(problem(std::string(200000, '\x81') + '\x00'), "byte 32: nested deeper than 32 levels");
    EXPECT_EQ(problem(std::string(200000, '\xc6') + '\x00'), "byte 32: nested deeper than 32 levels");  // tags
    EXPECT_EQ(problem(std::string("\x9b\x40\x00\x00\x00\x00\x00\x00\x00", 9)),
              "byte 0: 4611686018427387904 items claimed, with 0 bytes left");
    EXPECT_EQ(problem("\x5a\xff\xff\xff\xff"), "byte 0: a string longer than the data left");
    EXPECT_EQ(problem("\x82\x01"), "byte 0: 2 items claimed, with 1 bytes left");
    EXPECT_EQ(problem("\x9f\x01"), "byte 2: the data ends inside an item");
    EXPECT_EQ(problem("\x01\x02"), "byte 1: 1 bytes after the data item");
    EXPECT_EQ(problem("\xff"), "byte 0: a break outside an indefinite item");
    EXPECT_EQ(problem("\x1c"), "byte 0: a reserved head");
    EXPECT_EQ(problem("\x9f\x01\x82\x02\x03\xff"), "none");  // an indefinite array holding a definite one
    EXPECT_EQ(problem("\x7f\x61\x61\x01\xff"), "byte 3: an indefinite string holds something other than its chunks");
}

// Shard files as an attacker or a failing disk leaves them (the hostile
// audit's findings 1, 5 and 7): each refused with exit 2, naming the file,
// in bounded time and memory; never a crash, a hang or a silent merge.
TEST_F(Merge, RefusesHostileShardFiles) {
    const std::string work = "stress --only dead-ball --monte-carlo 0 --engines reference,exact --jobs 1";
    for (int k = 1; k <= 2; ++k)
        ASSERT_LE(test::bouncecheck(fmt::format("{} --shard {}/2 --out {}", work, k, at(fmt::format("s{}", k)))).status, 1);
    const auto refused = [&](const std::string& folder, const std::string& reason) {
        const auto r = test::bouncecheck(fmt::format("merge --out {} {} {}", at("merged"), at("s1"), at(folder)));
        EXPECT_EQ(r.status, 2) << folder << "\n" << r.output;
        EXPECT_NE(r.output.find(at(folder)), std::string::npos) << "the file is named\n" << r.output;
        EXPECT_NE(r.output.find(reason), std::string::npos) << folder << "\n" << r.output;
        EXPECT_FALSE(fs::exists(dir_ / "merged" / "stress.json")) << folder;
    };
    const auto shard_file = [&](const std::string& folder) {
        fs::create_directories(dir_ / folder);
        return dir_ / folder / kShardFileName;
    };
    // 1: 200,000 nested arrays: a stack overflow in the decoder.
    std::ofstream(shard_file("deep"), std::ios::binary) << std::string(200000, '\x81') << '\x00';
    refused("deep", "unreadable: byte 32: nested deeper than 32 levels");
    // 5: a FIFO in its place: refused at once.
    ASSERT_EQ(::mkfifo(shard_file("fifo").c_str(), 0600), 0);
    refused("fifo", "cannot read: not a regular file");
    // 7: one byte flipped where the CBOR stays valid: the digest notices.
    std::string bytes = slurp(dir_ / "s2" / kShardFileName);
    const auto at_option = bytes.find("dead-ball");
    ASSERT_NE(at_option, std::string::npos);
    bytes[at_option] = 'D';
    std::ofstream(shard_file("flipped"), std::ios::binary) << bytes;
    refused("flipped", "its digest does not match its contents");
    // 5: header counts no data backs, written with a right digest.
    const nlohmann::json j = nlohmann::json::from_cbor(slurp(dir_ / "s2" / kShardFileName));
    ShardFile forged;
    forged.command = "stress";
    forged.fingerprint = j.at("fingerprint").get<std::string>();
    forged.options = j.at("options");
    forged.shard = {2, 2147483647};
    write_shard_file(shard_file("count").parent_path(), forged);
    refused("count", "shard 2/2147483647 is not K/N with 1 <= K <= N <= 1000000");
    // Against another shard's header the count differs; every header agreeing
    // on a billion pairs that no shard holds would have sized the merge by it.
    forged.pairs = 1'000'000'000;
    forged.shard = {2, 2};
    write_shard_file(shard_file("pairs").parent_path(), forged);
    refused("pairs", "its pair count is 1000000000, not 2");
    forged.shard = {1, 2};
    write_shard_file(shard_file("pairs1").parent_path(), forged);
    const auto r = test::bouncecheck(fmt::format("merge --out {} {} {}", at("merged"), at("pairs1"), at("pairs")));
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("the shards hold 0 pairs, where their headers say the run has 1000000000"),
              std::string::npos)
        << r.output;
    // 1 again: the same nesting inside one result, behind a right digest: the
    // result is checked as the file is read, not left to crash the decoder.
    forged.shard = {2, 2};
    forged.pairs = 2;
    forged.slots = {1};
    forged.results = {std::string(200000, '\x81') + '\0'};
    write_shard_file(shard_file("deep-result").parent_path(), forged);
    refused("deep-result", "unreadable: result 1: byte 32: nested deeper than 32 levels");
    // The real pair still merges.
    EXPECT_LE(test::bouncecheck(fmt::format("merge --out {} {} {}", at("merged"), at("s1"), at("s2"))).status, 1);
}

// Shards of inputs other than the merge sees are refused: here a bundled
// stress scenario changed between the shards and the merge.
TEST_F(Merge, RefusesShardsOfInputsOtherThanTheMergeSees) {
    fs::copy(BOUNCECHECK_SCENARIO_DIR, dir_ / "scenarios", fs::copy_options::recursive);
    ASSERT_EQ(::setenv("BOUNCECHECK_SCENARIOS", (dir_ / "scenarios").c_str(), 1), 0);
    const std::string work = "stress --only dead-ball zero-gravity --engines reference,exact --jobs 1";
    for (int k = 1; k <= 2; ++k)
        ASSERT_LE(test::bouncecheck(fmt::format("{} --shard {}/2 --out {}", work, k, at(fmt::format("s{}", k)))).status, 1);
    const fs::path file = dir_ / "scenarios" / "stress" / "zero-gravity.toml";
    const std::string original = slurp(file);
    std::ofstream(file, std::ios::app) << "\n# a comment changes no scenario\n";
    const auto same = test::bouncecheck(fmt::format("merge {} {} {}", at("m1"), at("s1"), at("s2")));
    EXPECT_LE(same.status, 1) << same.output;
    const std::string text = slurp(dir_ / "m1" / "stress.json");  // no generated scenario: an empty array
    EXPECT_NE(text.find("\"generated_scenarios\": [],"), std::string::npos);
    EXPECT_EQ(nlohmann::json::parse(text).dump(2) + "\n", text);
    std::string changed = original;
    const auto radius = changed.find("radius = 0.05\n");
    ASSERT_NE(radius, std::string::npos);
    changed.replace(radius, 13, "radius = 0.051");  // another scenario
    std::ofstream(file, std::ios::trunc) << changed;
    const auto other = test::bouncecheck(fmt::format("merge {} {} {}", at("m2"), at("s1"), at("s2")));
    ::unsetenv("BOUNCECHECK_SCENARIOS");
    EXPECT_EQ(other.status, 2) << other.output;
    EXPECT_NE(other.output.find("the shards ran another build or other inputs than this merge sees"),
              std::string::npos)
        << other.output;
    EXPECT_FALSE(fs::exists(dir_ / "m2" / "stress.json"));
}

}  // namespace
