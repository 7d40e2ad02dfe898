// libFuzzer target for the report reader of `bouncecheck diff` and `run
// --baseline` (load_run_report, commands/diff/diff_pipeline.h): it reads a
// path, so each input is written to one file made once per process.
// load_run_report must answer every input with a report or a refusal naming
// the file, and throw nothing. A report it loads is then diffed against
// itself and rendered as `diff` does: a report equals itself, so every
// timing's ratio is 1 and no change may show. Anything else, or a crash or
// a sanitizer report, is a finding. `bouncecheck table` renders each loaded
// report too (reports/engine_table.h).
#include "commands/diff/diff_pipeline.h"

#include "reports/engine_table.h"
#include "reports/json_number.h"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <system_error>
#include <variant>

#include <unistd.h>

namespace {

[[noreturn]] void finding(const char* what, const std::string& detail) {
    std::fprintf(stderr, "fuzz_diff_report: %s\n%s\n", what, detail.c_str());
    std::abort();
}

// The file load_run_report reads, rewritten each iteration; removed at exit.
class ReportFile {
public:
    ReportFile() {
        path_ = (std::filesystem::temp_directory_path() / "fuzz_diff_report-XXXXXX").string();
        const int fd = ::mkstemp(path_.data());
        if (fd < 0) finding("cannot make the report file", path_);
        ::close(fd);
    }
    ~ReportFile() {
        std::error_code ec;
        std::filesystem::remove(path_, ec);
    }
    const std::string& write(const std::uint8_t* data, std::size_t size) const {
        std::FILE* out = std::fopen(path_.c_str(), "wb");
        if (!out || (size > 0 && std::fwrite(data, 1, size, out) != size) || std::fclose(out) != 0)
            finding("cannot write the report file", path_);
        return path_;
    }

private:
    std::string path_;
};

void check_self_diff(const bouncecheck::ReportDiff& d) {
    for (const bouncecheck::DiffChange& c : d.changes)
        finding("a report differs from itself", c.scenario + " / " + c.simulator + ": " + c.metric + ": " +
                                                    c.old_value + " -> " + c.new_value);
    for (const bouncecheck::TimingChange& t : d.timings)
        if (t.ratio != 1 || t.regression) finding("a run time differs from itself", t.scenario + " / " + t.simulator);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const ReportFile file;
    const std::string& path = file.write(data, size);
    try {
        const auto loaded = bouncecheck::load_run_report(path);
        if (const auto* refusal = std::get_if<std::string>(&loaded)) {
            if (refusal->rfind(path + ": ", 0) != 0 || refusal->size() == path.size() + 2)
                finding("a refusal that does not name the file and a reason", *refusal);
            return 0;
        }
        const auto& report = std::get<bouncecheck::LoadedReport>(loaded);
        // The default tolerances, and a timing ratio so that its judgement runs too.
        const bouncecheck::ReportDiff d = bouncecheck::diff_reports(report, report, bouncecheck::DiffTolerances{}, 1.0);
        check_self_diff(d);
        const bouncecheck::DiffDisplay all{.all = true, .timings = true};
        (void)bouncecheck::format_diff(d, all);
        (void)bouncecheck::diff_markdown(d, all);
        (void)bouncecheck::json_text(bouncecheck::diff_json(d), 2);
        // `bouncecheck table` renders what the same reader accepts.
        (void)bouncecheck::engine_table_markdown(report.json);
    } catch (const std::exception& e) {
        finding("an exception escaped", e.what());
    }
    return 0;
}
