// Small rigid-motion helpers for pose graphs, loop checks and hypothesis lists: the exponential and logarithm
// of rotations (axis-angle vectors), how far a transform moves the points of a scan, and whether two poses
// differ. Cost: O(1) each (centroid: O(n)).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace k4reg {

// Rotation matrix of the axis-angle vector w (|w| = angle in radians).
Eigen::Matrix3d rotation_exp(const Eigen::Vector3d& w);

// Axis-angle vector of a rotation matrix (angle in [0, pi]).
Eigen::Vector3d rotation_log(const Eigen::Matrix3d& r);

// Where a scan's points lie, in its own frame: their centre and their radius about it.
struct ScanExtent {
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
};

// How far a transform that should be the identity moves the points of a scan, in metres:
// sqrt(|T c - c|^2 + (radius * angle)^2), c the scan's centre. One number for rotation and translation, in the
// units a user judges a registration by; measured at the scan, so it does not depend on where its file puts its
// origin (about an origin 40 m away, a twentieth of a degree would count as centimetres).
double displacement_m(const Eigen::Matrix4d& t, const ScanExtent& scan);

// How far apart two poses put the point at_m (in the posed scan's own frame).
double shift_at_m(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b, const Eigen::Vector3d& at_m);

// Whether two poses of one scan differ: by at least min_angle_deg, or by putting the point at_m (the scan's
// centre, in its own frame) at least min_shift_m apart. Compared at the scan rather than at its frame's origin:
// an origin tens of metres away turns a fraction of a degree into centimetres of translation.
bool distinct_transforms(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b, const Eigen::Vector3d& at_m,
                         double min_angle_deg, double min_shift_m);

// The mean of the points, in double (zero for none): the centre poses are compared and rotated about.
Eigen::Vector3d centroid(const std::vector<Eigen::Vector3f>& points);

// The inverse of a rigid transform.
Eigen::Matrix4d rigid_inverse(const Eigen::Matrix4d& t);

}  // namespace k4reg
