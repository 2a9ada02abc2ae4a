#include "k4reg/registration/translation_constraint.h"

#include <Eigen/Eigenvalues>
#include <algorithm>

namespace k4reg {

Eigen::Matrix3d normalized_constraint(const Eigen::Matrix3d& information) {
  const double trace = information.trace();
  return trace > 0 ? Eigen::Matrix3d(3.0 * information / trace) : Eigen::Matrix3d::Zero();
}

std::array<double, 3> axis_constraint(const Eigen::Matrix3d& constraint) {
  return {constraint(0, 0), constraint(1, 1), constraint(2, 2)};
}

double weakest_constraint(const Eigen::Matrix3d& constraint) {
  const Eigen::Matrix3d symmetric = 0.5 * (constraint + constraint.transpose());
  return std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(symmetric, Eigen::EigenvaluesOnly).eigenvalues()(0));
}

Eigen::Matrix3d rotated_constraint(const Eigen::Matrix3d& constraint, const Eigen::Matrix3d& rotation) {
  return rotation * constraint * rotation.transpose();
}

}  // namespace k4reg
