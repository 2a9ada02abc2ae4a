// Small rigid-motion helpers for pose graphs and loop checks: the exponential and logarithm of rotations
// (axis-angle vectors) and how far a transform moves the points of a scan. Cost: O(1) each.
#pragma once

#include <Eigen/Core>

namespace k4reg {

// Rotation matrix of the axis-angle vector w (|w| = angle in radians).
Eigen::Matrix3d rotation_exp(const Eigen::Vector3d& w);

// Axis-angle vector of a rotation matrix (angle in [0, pi]).
Eigen::Vector3d rotation_log(const Eigen::Matrix3d& r);

// How far a transform that should be the identity moves the points of a scan of radius lever_arm_m about
// the frame's origin, in metres: sqrt(|t|^2 + (lever_arm_m * angle)^2). One number for rotation and
// translation, in the units a user judges a registration by.
double displacement_m(const Eigen::Matrix4d& t, double lever_arm_m);

// The inverse of a rigid transform.
Eigen::Matrix4d rigid_inverse(const Eigen::Matrix4d& t);

}  // namespace k4reg
