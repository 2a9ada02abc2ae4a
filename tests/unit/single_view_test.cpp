// Whether a scan is one range camera's view of an object, and from where: a dome seen from above is, from
// whichever sign its normals come with; a room seen from inside is not.
#include <gtest/gtest.h>

#include <cmath>

#include "k4reg/registration/single_view.h"

namespace k4reg {
namespace {

struct Cloud {
  std::vector<Eigen::Vector3f> points, normals;
};

// The upper half of a 0.1 m sphere, as a camera far above returns it; normals of alternating sign (a local
// plane fit cannot tell the sides apart).
Cloud dome() {
  Cloud c;
  int i = 0;
  for (float x = -0.1f; x <= 0.1f; x += 0.002f)
    for (float y = -0.1f; y <= 0.1f; y += 0.002f)
      if (x * x + y * y < 0.0095f) {
        const Eigen::Vector3f p(x, y, std::sqrt(0.01f - x * x - y * y));
        c.points.push_back(p);
        c.normals.push_back((i++ % 2 ? 1.0f : -1.0f) * p.normalized());
      }
  return c;
}

// The walls, floor and ceiling of a 6 x 4 x 3 m room around its scanner.
Cloud room() {
  Cloud c;
  const Eigen::Vector3f half(3, 2, 1.5f);
  for (int axis = 0; axis < 3; ++axis)
    for (const float side : {-1.0f, 1.0f}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (float a = -half(u); a <= half(u); a += 0.1f)
        for (float b = -half(v); b <= half(v); b += 0.1f) {
          Eigen::Vector3f p;
          p(axis) = side * half(axis), p(u) = a, p(v) = b;
          c.points.push_back(p);
          c.normals.push_back(Eigen::Vector3f::Unit(axis));
        }
    }
  return c;
}

TEST(SingleView, ADomeSeenFromAboveFacesUp) {
  const Cloud c = dome();
  const auto toward = single_view_direction(c.points, c.normals);
  ASSERT_TRUE(toward.has_value());
  EXPECT_GT(toward->dot(Eigen::Vector3f::UnitZ()), std::cos(5.0 * M_PI / 180));
  // Turned upside down, it faces down.
  std::vector<Eigen::Vector3f> flipped = c.points;
  for (Eigen::Vector3f& p : flipped) p = -p;
  const auto down = single_view_direction(flipped, c.normals);
  ASSERT_TRUE(down.has_value());
  EXPECT_GT(down->dot(-Eigen::Vector3f::UnitZ()), std::cos(5.0 * M_PI / 180));
}

TEST(SingleView, ARoomAroundItsScannerIsNotASingleView) {
  const Cloud c = room();
  EXPECT_FALSE(single_view_direction(c.points, c.normals).has_value());
}

TEST(SingleView, UnknownNormalsAreIgnoredAndTooFewSayNothing) {
  Cloud c = dome();
  for (std::size_t i = 0; i < c.normals.size(); ++i)
    if (i % 3) c.normals[i].setZero();
  EXPECT_TRUE(single_view_direction(c.points, c.normals).has_value());
  c.normals.resize(60);
  c.points.resize(60);
  EXPECT_FALSE(single_view_direction(c.points, c.normals).has_value());
}

}  // namespace
}  // namespace k4reg
