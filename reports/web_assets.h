// The files a self-contained HTML page inlines, embedded in the binary at
// build time (reports/html/web_assets.S.in): the charting library from
// web/package.json's lock file, and the pages' own script and style.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace bouncecheck {

std::string_view plotly_js();   // plotly.js-dist-min, minified
std::string_view page_js();     // reports/html/page.js: builds every plot and table from the page's data
std::string_view animation_js();  // reports/html/animation.js: the per-scenario animation page.js creates
std::string_view page_css();    // reports/html/page.css

// The page: title, style, the library, the data (JSON) and the page script,
// each inlined, so that it opens from disk with no request to any server.
// In three pieces that, written one after another, make the page: the
// library between them is a view of the binary's own copy, so the page is
// written without copying it (write_page).
struct Page {
    std::string head;          // up to the library
    std::string_view library;  // plotly_js()
    std::string tail;          // the data and the page script
    std::string text() const;  // the whole page, joined (for reading it back)
};
// `data_json` must be JSON text; it is escaped for a <script> element here.
Page self_contained_page(std::string_view title, std::string_view data_json);
// Writes the page to `target` atomically.
void write_page(const std::filesystem::path& target, const Page& page);

}  // namespace bouncecheck
