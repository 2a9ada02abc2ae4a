#include "peers/peer_reply.h"

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <fmt/format.h>

namespace k4reg::service {
namespace {

constexpr double kRigidTolerance = 1e-4;  // far above rounding of a rotation, far below any real shear

bool finite_values(const google::protobuf::RepeatedField<double>& values) {
  for (const double value : values)
    if (!std::isfinite(value)) return false;
  return true;
}

}  // namespace

std::string reply_problem(const v1::RegisterPairResponse& reply, std::size_t source_points, std::size_t target_points) {
  if (!reply.has_result()) return "no result";
  const v1::RegistrationResult& result = reply.result();
  if (result.source_points() != source_points || result.target_points() != target_points)
    return fmt::format("a result for clouds of {} and {} points, not the {} and {} sent", result.source_points(),
                       result.target_points(), source_points, target_points);
  if (result.transform_size() != 16) return fmt::format("a transform of {} numbers, not 16", result.transform_size());
  if (!finite_values(result.transform()) || !finite_values(result.constraint()) ||
      !finite_values(result.axis_constraint()))
    return "a NaN or infinite number";
  for (const double value : {result.rmse_m(), result.overlap(), result.ambiguity_margin(), result.min_scale_m_used(),
                             result.overlap_used(), result.weakest_constraint()})
    if (!std::isfinite(value)) return "a NaN or infinite number";
  for (const v1::Hypothesis& hypothesis : result.hypotheses())
    if (!finite_values(hypothesis.transform())) return "a NaN or infinite number";
  const Eigen::Matrix4d transform = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(result.transform().data());
  const Eigen::Matrix3d rotation = transform.topLeftCorner<3, 3>();
  if (!transform.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1)) ||
      !(rotation.transpose() * rotation).isIdentity(kRigidTolerance) || rotation.determinant() <= 0)
    return "a transform that is not rigid";
  return {};
}

}  // namespace k4reg::service
