#include "k4reg/registration/single_view.h"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace k4reg {

std::optional<Eigen::Vector3f> single_view_direction(const std::vector<Eigen::Vector3f>& points,
                                                     const std::vector<Eigen::Vector3f>& normals) {
  constexpr float kGrazingCos = 0.26f;        // 75 degrees
  constexpr double kMaxGrazingShare = 1.0 / 3.0;
  constexpr std::size_t kMinNormals = 100;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  std::size_t known = 0;
  for (std::size_t i = 0; i < points.size() && i < normals.size(); ++i) {
    if (normals[i].squaredNorm() < 0.5f) continue;
    const Eigen::Vector3d n = normals[i].cast<double>();
    scatter += n * n.transpose();
    centroid += points[i].cast<double>();
    ++known;
  }
  if (known < kMinNormals) return std::nullopt;
  centroid /= static_cast<double>(known);
  Eigen::Vector3f toward = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(2).cast<float>();
  // A normal's sign is arbitrary: each is turned toward the axis, and the surfaces face the camera, so they
  // face outward from the object; on a convex view that is away from the centroid.
  double outward = 0;
  std::size_t grazing = 0;
  for (std::size_t i = 0; i < points.size() && i < normals.size(); ++i) {
    if (normals[i].squaredNorm() < 0.5f) continue;
    const float along = normals[i].dot(toward);
    grazing += std::abs(along) < kGrazingCos;
    outward += (along < 0 ? -1.0 : 1.0) * normals[i].cast<double>().dot(points[i].cast<double>() - centroid);
  }
  if (static_cast<double>(grazing) > kMaxGrazingShare * static_cast<double>(known)) return std::nullopt;
  return outward >= 0 ? toward : Eigen::Vector3f(-toward);
}

}  // namespace k4reg
