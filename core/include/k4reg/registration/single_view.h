// Whether a scan is one range camera's view of an object, and from which direction. Every surface such a
// camera returned from faced it, so the scan's normals cluster about the direction toward the camera and
// few lie near grazing incidence to it: 6-26 % of them beyond 75 degrees on the Stanford bunny's ten views
// and the simulated statuettes. A terrestrial scan surrounds its scanner (walls at every azimuth, floor and
// ceiling): whatever direction its normals favour, 44-54 % of them lie beyond 75 degrees to it (simulated
// lab, hall, courtyard), and 35-36 % on one scan of each of the 3DMatch and ETH office pairs.
// Such a view's free space (free_space.h, parallel) is then known without the camera's position, which a
// scan moved by an unknown motion does not keep.
// Cost: normals at the given points (a voxel grid), O(n).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

namespace k4reg {

// The unit direction toward the camera (the dominant axis of the normals, turned to the side the surfaces
// face: outward from the points' centroid), or nothing where more than a third of the normals lie beyond
// 75 degrees to it. normals: zero where unknown (ignored).
std::optional<Eigen::Vector3f> single_view_direction(const std::vector<Eigen::Vector3f>& points,
                                                     const std::vector<Eigen::Vector3f>& normals);

}  // namespace k4reg
