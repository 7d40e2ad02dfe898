#include "reports/web_assets.h"

#include "platform/atomic_file.h"
#include "reports/run_report.h"

#include <fmt/format.h>

#include <cstddef>

extern "C" {
extern const char bouncecheck_asset_plotly_js[], bouncecheck_asset_plotly_js_end[];
extern const char bouncecheck_asset_page_js[], bouncecheck_asset_page_js_end[];
extern const char bouncecheck_asset_animation_js[], bouncecheck_asset_animation_js_end[];
extern const char bouncecheck_asset_page_css[], bouncecheck_asset_page_css_end[];
}

namespace bouncecheck {

namespace {

std::string_view span(const char* begin, const char* end) {
    return {begin, static_cast<std::size_t>(end - begin)};
}

// Inside <script>, "</" could close the element early (a scenario named
// "</script>"), and "<!--" followed by "<script" makes the parser swallow
// the real "</script>", blanking the page (an external's stderr can hold
// either). JSON has "<" only inside strings, where "\u003c" is the same
// character to JSON and to JavaScript: no "<" is left at all.
std::string script_safe_json(std::string_view json) {
    std::string out;
    out.reserve(json.size() + 16);
    for (const char c : json) {
        if (c == '<') out += "\\u003c";
        else out += c;
    }
    return out;
}


}  // namespace

std::string_view plotly_js() { return span(bouncecheck_asset_plotly_js, bouncecheck_asset_plotly_js_end); }
std::string_view page_js() { return span(bouncecheck_asset_page_js, bouncecheck_asset_page_js_end); }
std::string_view animation_js() {
    return span(bouncecheck_asset_animation_js, bouncecheck_asset_animation_js_end);
}
std::string_view page_css() { return span(bouncecheck_asset_page_css, bouncecheck_asset_page_css_end); }

Page self_contained_page(std::string_view title, std::string_view data_json) {
    Page page;
    page.head = fmt::format(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
        // Nothing may leave the page: no server is asked for anything.
        "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; "
        "script-src 'unsafe-inline' 'unsafe-eval'; style-src 'unsafe-inline'; img-src data: blob:; "
        "worker-src blob:\">\n"
        "<title>{}</title>\n<style>\n{}</style>\n"
        "<script>\n",
        xml_escape(title), page_css());
    page.library = plotly_js();
    page.tail = fmt::format(
        "\n</script>\n"
        "<script id=\"bouncecheck-data\" type=\"application/json\">{}</script>\n"
        "</head>\n<body>\n<main id=\"page\"></main>\n<script>\n{}\n{}\n</script>\n</body>\n</html>\n",
        script_safe_json(data_json), animation_js(), page_js());
    return page;
}

std::string Page::text() const {
    std::string out;
    out.reserve(head.size() + library.size() + tail.size());
    return out.append(head).append(library).append(tail);
}

void write_page(const std::filesystem::path& target, const Page& page) {
    write_file_atomically(target, {page.head, page.library, page.tail});
}

}  // namespace bouncecheck
