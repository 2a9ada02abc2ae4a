// The document the QA view shows (web/view/): what was registered, with which parameters, the result as
// `--json` prints it and the preview of the registered clouds (float32 arrays as base64). The CLI's `--report`
// writes it into the page; the server's page builds the same from the HTTP API's answer.
// Cost: the preview's bytes, a third more as base64 (about 21 bytes per preview point in all).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "k4reg/qa/cloud_preview.h"

namespace k4reg::web {

struct ReportDocument {
  std::string kind;                 // "pair" or "project"
  std::string title;                // e.g. "scan2.ply -> scan1.ply"
  std::string generator;            // the command that made it, e.g. "k4reg align"
  std::vector<std::string> files;   // pair: source, target; project: one label per scan
  nlohmann::json parameters = nlohmann::json::object();  // as given
  nlohmann::json result;            // as the command's --json prints it
  const CloudPreview* preview = nullptr;  // none: the view shows the figures only
};

std::string base64(std::string_view bytes);

// {"offset_m", "distance_cap_m", "clouds": [{"name", "points", "xyz", "distance_m", "keypoints_xyz"}]}, the
// arrays as base64 of little-endian float32 (the same names and encoding as the API's Preview message in JSON).
nlohmann::json preview_to_json(const CloudPreview& preview);

nlohmann::json to_json(const ReportDocument& document);

// The self-contained report page (web_page.h) with the document in it. Throws k4reg::Error(kInvalidArgument)
// naming the path when it cannot be written.
void write_report(const std::string& path, const ReportDocument& document);

}  // namespace k4reg::web
