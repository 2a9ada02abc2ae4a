// The QA report page: base64 as RFC 4648 has it, every marker of the template filled, a document that cannot
// close its script element early, previews encoded as the API's Preview, and a path that cannot be written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "k4reg/util/error.h"
#include "report_document.h"
#include "web_page.h"

namespace k4reg::web {
namespace {

TEST(ReportDocument, Base64AsRfc4648) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64(std::string("\xff\x00\x80", 3)), "/wCA");
}

TEST(ReportDocument, ThePageHasEveryAssetAndNoNetworkAddress) {
  const std::string page = render_page(nullptr);
  EXPECT_EQ(page.find("/*K4REG:"), std::string::npos);
  EXPECT_NE(page.find("OrbitControls"), std::string::npos);
  for (const char* name : {"view/helpers.js", "view/model.js", "view/cards.js", "view/charts.js", "view/tables.js",
                           "view/scene3d.js", "view/slice.js", "view/render_view.js", "app.js"}) {
    ASSERT_FALSE(asset(name).empty()) << name;
    EXPECT_NE(page.find(asset(name).substr(0, 200)), std::string::npos) << name;
  }
  EXPECT_EQ(page.find("http://"), std::string::npos);
  EXPECT_EQ(page.find("https://"), std::string::npos);
  EXPECT_TRUE(asset("no-such-file.js").empty());
}

TEST(ReportDocument, AFileNameCannotEndTheDocumentsScriptElement) {
  ReportDocument document;
  document.kind = "pair";
  document.files = {"</script><script>alert(1)</script>.ply", "b.ply"};
  document.result = nlohmann::json::object();
  const std::string page = render_page(to_json(document));
  EXPECT_EQ(page.find("</script><script>alert(1)"), std::string::npos);
  EXPECT_NE(page.find("<\\/script><script>alert(1)<\\/script>.ply"), std::string::npos);
}

TEST(ReportDocument, PreviewArraysAreLittleEndianFloat32InBase64) {
  CloudPreview preview;
  preview.offset_m = {1.0, 2.0, 3.0};
  preview.distance_cap_m = 0.5;
  PreviewCloud& cloud = preview.clouds.emplace_back();
  cloud.name = "source";
  cloud.points = 7;
  cloud.xyz = {Eigen::Vector3f(1.0f, 0.0f, -2.0f)};
  cloud.distance_m = {0.25f};
  const nlohmann::json json = preview_to_json(preview);
  EXPECT_EQ(json["offset_m"], nlohmann::json({1.0, 2.0, 3.0}));
  EXPECT_EQ(json["clouds"][0]["points"], 7);
  EXPECT_EQ(json["clouds"][0]["xyz"], "AACAPwAAAAAAAADA");  // 1.0f, 0.0f, -2.0f
  EXPECT_EQ(json["clouds"][0]["distance_m"], "AACAPg==");   // 0.25f
  EXPECT_EQ(json["clouds"][0]["keypoints_xyz"], "");
}

TEST(ReportDocument, AnUnwritablePathIsAnError) {
  ReportDocument document;
  document.result = nlohmann::json::object();
  EXPECT_THROW(write_report("/nonexistent-folder/r.html", document), Error);
  const std::string path = testing::TempDir() + "report_document_test.html";
  write_report(path, document);
  EXPECT_GT(std::filesystem::file_size(path), asset("three.min.js").size());
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace k4reg::web
