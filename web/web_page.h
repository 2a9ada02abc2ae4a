// The QA view as one self-contained HTML page: web/k4reg.html with its style sheet and scripts (ours and
// three.js r111 from Debian's libjs-three) inlined, so it opens offline and references no network address.
// With a result document (report_document.h) it is the report `--report` writes; without one it is the page
// the server serves at GET /, which uploads scans through the HTTP API and shows the result with the same code.
// Cost: one copy of about 1 MB of assets plus the document.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace k4reg::web {

// An embedded file by name: its path under web/ ("k4reg.html", "view/model.js") or, for three.js, its file name
// ("three.min.js", "OrbitControls.js"); empty when there is none.
std::string_view asset(std::string_view name);

// The page; `document` null = the server's upload page.
std::string render_page(const nlohmann::json& document);

}  // namespace k4reg::web
