#include "report_document.h"

#include <bit>
#include <chrono>
#include <cstring>
#include <fstream>

#include "k4reg/util/error.h"
#include "web_page.h"

namespace k4reg::web {
namespace {

static_assert(std::endian::native == std::endian::little, "previews are little-endian float32: add a byte swap");

// The floats' bytes as base64.
template <typename T>
std::string floats_base64(const std::vector<T>& values) {
  return base64(std::string_view(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T)));
}
static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float), "Vector3f must be three packed floats");

std::string utc_now() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

}  // namespace

std::string base64(std::string_view bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const std::uint32_t v = std::uint8_t(bytes[i]) << 16 | std::uint8_t(bytes[i + 1]) << 8 | std::uint8_t(bytes[i + 2]);
    out += {kAlphabet[v >> 18], kAlphabet[(v >> 12) & 63], kAlphabet[(v >> 6) & 63], kAlphabet[v & 63]};
  }
  if (i + 1 == bytes.size()) {
    const std::uint32_t v = std::uint8_t(bytes[i]) << 16;
    out += {kAlphabet[v >> 18], kAlphabet[(v >> 12) & 63], '=', '='};
  } else if (i + 2 == bytes.size()) {
    const std::uint32_t v = std::uint8_t(bytes[i]) << 16 | std::uint8_t(bytes[i + 1]) << 8;
    out += {kAlphabet[v >> 18], kAlphabet[(v >> 12) & 63], kAlphabet[(v >> 6) & 63], '='};
  }
  return out;
}

nlohmann::json preview_to_json(const CloudPreview& preview) {
  nlohmann::json clouds = nlohmann::json::array();
  for (const PreviewCloud& cloud : preview.clouds)
    clouds.push_back({{"name", cloud.name},
                      {"points", cloud.points},
                      {"xyz", floats_base64(cloud.xyz)},
                      {"distance_m", floats_base64(cloud.distance_m)},
                      {"keypoints_xyz", floats_base64(cloud.keypoints)}});
  return {{"offset_m", {preview.offset_m.x(), preview.offset_m.y(), preview.offset_m.z()}},
          {"distance_cap_m", preview.distance_cap_m},
          {"clouds", std::move(clouds)}};
}

nlohmann::json to_json(const ReportDocument& document) {
  return {{"kind", document.kind},
          {"title", document.title},
          {"generator", document.generator},
          {"created", utc_now()},
          {"files", document.files},
          {"parameters", document.parameters},
          {"result", document.result},
          {"preview", document.preview ? preview_to_json(*document.preview) : nlohmann::json(nullptr)}};
}

void write_report(const std::string& path, const ReportDocument& document) {
  const std::string page = render_page(to_json(document));
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(page.data(), static_cast<std::streamsize>(page.size()));
  out.close();
  if (!out) fail(ErrorCode::kInvalidArgument, "cannot write the report " + path);
}

}  // namespace k4reg::web
