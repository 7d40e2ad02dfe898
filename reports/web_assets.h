// The files a self-contained HTML page inlines, embedded in the binary at
// build time (reports/html/web_assets.S.in): the charting library from
// web/package.json's lock file, and the pages' own script and style.
#pragma once

#include <string>
#include <string_view>

namespace bouncecheck {

std::string_view plotly_js();   // plotly.js-dist-min, minified
std::string_view page_js();     // reports/html/page.js: builds every plot and table from the page's data
std::string_view page_css();    // reports/html/page.css

// The page: title, style, the library, the data (JSON) and the page script,
// each inlined, so that it opens from disk with no request to any server.
// `data_json` must be JSON text; it is escaped for a <script> element here.
std::string self_contained_page(std::string_view title, std::string_view data_json);

}  // namespace bouncecheck
