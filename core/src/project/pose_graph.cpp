#include "k4reg/project/pose_graph.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <vector>

#include "k4reg/geometry/rigid_motion.h"
#include "k4reg/util/error.h"

namespace k4reg {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// Left perturbation of a pose: exp(delta) * pose, delta = [rotation; translation] in the project frame.
Eigen::Matrix4d perturbed(const Eigen::Matrix4d& pose, const Vector6d& delta) {
  Eigen::Matrix4d step = Eigen::Matrix4d::Identity();
  step.topLeftCorner<3, 3>() = rotation_exp(delta.head<3>());
  step.topRightCorner<3, 1>() = delta.tail<3>();
  return step * pose;
}

Vector6d residual(const Eigen::Matrix4d& from, const Eigen::Matrix4d& to, const PoseGraphLink& link) {
  const Eigen::Matrix4d misfit = link_misfit(from, to, link.measured);
  Vector6d r;
  const Eigen::Vector3d& centre = link.from_extent.centre_m;
  r.head<3>() = link.from_extent.radius_m * rotation_log(misfit.topLeftCorner<3, 3>());
  r.tail<3>() = misfit.topLeftCorner<3, 3>() * centre + misfit.topRightCorner<3, 1>() - centre;
  return r;
}

double huber_weight(double norm, double huber_m) { return huber_m > 0 && norm > huber_m ? huber_m / norm : 1.0; }

double total_cost(const std::vector<Eigen::Matrix4d>& poses, const std::vector<PoseGraphLink>& links, double huber_m) {
  double cost = 0.0;
  for (const PoseGraphLink& link : links) {
    const double n = residual(poses[link.from], poses[link.to], link).norm();
    // Huber's rho: quadratic inside, linear outside.
    cost += link.weight * (huber_m > 0 && n > huber_m ? huber_m * (2 * n - huber_m) : n * n);
  }
  return cost;
}

}  // namespace

Eigen::Matrix4d link_misfit(const Eigen::Matrix4d& from_pose, const Eigen::Matrix4d& to_pose,
                            const Eigen::Matrix4d& measured) {
  return rigid_inverse(measured) * rigid_inverse(to_pose) * from_pose;
}

PoseGraphResult optimize_pose_graph(const std::vector<Eigen::Matrix4d>& initial,
                                    const std::vector<PoseGraphLink>& links, const PoseGraphParams& params) {
  const std::size_t n = initial.size();
  if (params.fixed >= n) fail(ErrorCode::kInvalidArgument, "pose graph: the fixed scan is out of range");
  for (const PoseGraphLink& link : links)
    if (link.from >= n || link.to >= n || link.from == link.to || !(link.weight > 0) ||
        !(link.from_extent.radius_m >= 0) || !link.from_extent.centre_m.allFinite())
      fail(ErrorCode::kInvalidArgument, "pose graph: a link has bad scan indices, weight or extent");

  // Unknown block of each scan (the fixed one has none).
  std::vector<int> block(n, -1);
  int unknowns = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (i != params.fixed) block[i] = unknowns++;

  PoseGraphResult out;
  out.poses = initial;
  out.initial_cost = out.final_cost = total_cost(out.poses, links, params.huber_m);
  double lambda = 1e-4;
  constexpr double kStep = 1e-7;  // numeric derivative step (radians or metres)
  for (int it = 0; it < params.max_iterations && unknowns > 0; ++it) {
    out.iterations = it + 1;
    std::vector<Eigen::Triplet<double>> triplets;
    Eigen::VectorXd gradient = Eigen::VectorXd::Zero(6 * unknowns);
    for (const PoseGraphLink& link : links) {
      const Vector6d r = residual(out.poses[link.from], out.poses[link.to], link);
      const double w = link.weight * huber_weight(r.norm(), params.huber_m);
      // Central differences with respect to each end's perturbation.
      Matrix6d jacobian[2] = {Matrix6d::Zero(), Matrix6d::Zero()};
      for (int end = 0; end < 2; ++end)
        for (int k = params.levelled ? 2 : 0; k < 6; ++k) {  // levelled: no rotation about x or y
          Vector6d d = Vector6d::Zero();
          d(k) = kStep;
          const std::size_t s = end == 0 ? link.from : link.to;
          auto at = [&](const Vector6d& delta) {
            const Eigen::Matrix4d moved = perturbed(out.poses[s], delta);
            return end == 0 ? residual(moved, out.poses[link.to], link) : residual(out.poses[link.from], moved, link);
          };
          jacobian[end].col(k) = (at(d) - at(-d)) / (2 * kStep);
        }
      const std::size_t ends[2] = {link.from, link.to};
      for (int a = 0; a < 2; ++a) {
        if (block[ends[a]] < 0) continue;
        gradient.segment<6>(6 * block[ends[a]]) += w * jacobian[a].transpose() * r;
        for (int b = 0; b < 2; ++b) {
          if (block[ends[b]] < 0) continue;
          const Matrix6d h = w * jacobian[a].transpose() * jacobian[b];
          for (int i = 0; i < 6; ++i)
            for (int j = 0; j < 6; ++j) triplets.emplace_back(6 * block[ends[a]] + i, 6 * block[ends[b]] + j, h(i, j));
        }
      }
    }
    Eigen::SparseMatrix<double> hessian(6 * unknowns, 6 * unknowns);
    hessian.setFromTriplets(triplets.begin(), triplets.end());
    // Levenberg-Marquardt: damp until a step lowers the cost (a scan no link reaches stays where it is).
    bool improved = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Eigen::SparseMatrix<double> damped = hessian;
      for (int i = 0; i < 6 * unknowns; ++i) damped.coeffRef(i, i) += lambda * (1.0 + hessian.coeff(i, i));
      const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(damped);
      if (solver.info() != Eigen::Success) {
        lambda *= 10;
        continue;
      }
      const Eigen::VectorXd step = solver.solve(-gradient);
      std::vector<Eigen::Matrix4d> trial = out.poses;
      for (std::size_t i = 0; i < n; ++i)
        if (block[i] >= 0) trial[i] = perturbed(trial[i], step.segment<6>(6 * block[i]));
      const double cost = total_cost(trial, links, params.huber_m);
      if (cost < out.final_cost) {
        const double gain = out.final_cost - cost;
        out.poses = std::move(trial);
        out.final_cost = cost;
        lambda = std::max(lambda / 10, 1e-9);
        improved = true;
        if (gain < 1e-12 * (1.0 + cost)) it = params.max_iterations;  // converged
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  for (const PoseGraphLink& link : links)
    out.residual_m.push_back(displacement_m(link_misfit(out.poses[link.from], out.poses[link.to], link.measured),
                                            link.from_extent));
  return out;
}

PoseGraphResult optimize_pose_graph_robustly(const std::vector<Eigen::Matrix4d>& initial,
                                             const std::vector<PoseGraphLink>& links, const PoseGraphParams& params) {
  constexpr int kMaxTightenings = 4;
  PoseGraphResult solved = optimize_pose_graph(initial, links, params);
  if (links.size() < 3) return solved;
  PoseGraphParams tighter = params;
  for (int round = 0; round < kMaxTightenings; ++round) {
    std::vector<double> residuals = solved.residual_m;
    std::nth_element(residuals.begin(), residuals.begin() + residuals.size() / 2, residuals.end());
    const double scale_m = 2.0 * residuals[residuals.size() / 2];
    // Only while the scale shrinks clearly: once it settles, the links agree as well as they can.
    if (!(scale_m > 0.0 && (tighter.huber_m <= 0.0 || scale_m < 0.9 * tighter.huber_m))) break;
    tighter.huber_m = scale_m;
    solved = optimize_pose_graph(solved.poses, links, tighter);
  }
  return solved;
}

}  // namespace k4reg
