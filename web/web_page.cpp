#include "web_page.h"

#include <stdexcept>

namespace k4reg::web {
namespace {

// JSON inside <script type="application/json">: "</" would end the element early; "<\/" is the same JSON.
std::string script_safe(const std::string& json) {
  std::string out;
  out.reserve(json.size());
  for (std::size_t i = 0; i < json.size(); ++i) {
    out += json[i];
    if (json[i] == '<' && i + 1 < json.size() && json[i + 1] == '/') out += '\\';
  }
  return out;
}

}  // namespace

std::string render_page(const nlohmann::json& document) {
  const std::string_view page = asset("k4reg.html");
  // Invalid UTF-8 (a file name, say) becomes U+FFFD rather than an exception.
  const std::string json = script_safe(document.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  // Each marker /*K4REG:name*/ of the template, in order, becomes the document or the named asset; what is filled
  // in is never searched again, whatever it contains.
  constexpr std::string_view kOpen = "/*K4REG:", kClose = "*/";
  std::string out;
  out.reserve(page.size() + json.size() + (1 << 20));
  std::size_t done = 0;
  for (std::size_t at = page.find(kOpen); at != std::string_view::npos; at = page.find(kOpen, done)) {
    const std::size_t end = page.find(kClose, at + kOpen.size());
    if (end == std::string_view::npos) throw std::logic_error("k4reg.html: an unclosed marker");
    const std::string_view name = page.substr(at + kOpen.size(), end - at - kOpen.size());
    const std::string_view text = name == "document" ? std::string_view(json) : asset(name);
    if (text.empty()) throw std::logic_error("k4reg.html: no asset " + std::string(name));
    out.append(page.substr(done, at - done)).append(text);
    done = end + kClose.size();
  }
  out.append(page.substr(done));
  return out;
}

}  // namespace k4reg::web
