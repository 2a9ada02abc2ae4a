#!/usr/bin/python3
"""Open3D 0.16's global registration of one pair: the Open3D peers of k4reg-bench-compare (run by its worker,
see bench/open3d_peer.h). Needs Debian's python3-open3d (not in scripts/install-deps.sh: about 180 MB).

    open3d_pair.py --method ransac|fgr --voxel V --seed N SOURCE.ply TARGET.ply

Open3D's global registration tutorial, every parameter scaled from one voxel size V (the job's sigma):
  - each cloud: voxel_down_sample(V); normals, KDTreeSearchParamHybrid(2 V, 30); FPFH, KDTreeSearchParamHybrid(5 V, 100)
  - ransac: registration_ransac_based_on_feature_matching, mutual filter, distance 1.5 V, point-to-point,
    ransac_n 3, checkers edge length 0.9 and distance 1.5 V, RANSACConvergenceCriteria(100000, 0.999)
  - fgr: registration_fgr_based_on_feature_matching, FastGlobalRegistrationOption(maximum_correspondence_distance=0.5 V)
  - o3d.utility.random.seed(N), so a trial repeats. No ICP afterwards (the comparison's PCL methods get none).
Threads: OpenMP, OMP_NUM_THREADS from the caller.

Prints one JSON line: "transform" (16 numbers, row-major, source -> target in the files' frame), "seconds" (from
both clouds in memory to the transform: down-sampling, normals, FPFH, matching), "read_s" (the two files),
"stages" {"features", "matching"}, "source_points" / "target_points" (after down-sampling), "fitness", "inlier_rmse".
"""
import argparse
import json
import time

import numpy as np
import open3d as o3d

reg = o3d.pipelines.registration


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--method", choices=["ransac", "fgr"], required=True)
    ap.add_argument("--voxel", type=float, required=True, help="voxel size V, in the files' units")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("source")
    ap.add_argument("target")
    a = ap.parse_args()
    v = a.voxel
    o3d.utility.random.seed(a.seed)
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)

    t = time.perf_counter()
    clouds = [o3d.io.read_point_cloud(path) for path in (a.source, a.target)]
    read_s = time.perf_counter() - t

    start = time.perf_counter()
    described = []
    for pcd in clouds:
        down = pcd.voxel_down_sample(v)
        down.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=2 * v, max_nn=30))
        fpfh = reg.compute_fpfh_feature(down, o3d.geometry.KDTreeSearchParamHybrid(radius=5 * v, max_nn=100))
        described.append((down, fpfh))
    features_s = time.perf_counter() - start
    (source, source_fpfh), (target, target_fpfh) = described

    t = time.perf_counter()
    if a.method == "ransac":
        result = reg.registration_ransac_based_on_feature_matching(
            source, target, source_fpfh, target_fpfh, True, 1.5 * v,
            reg.TransformationEstimationPointToPoint(False), 3,
            [reg.CorrespondenceCheckerBasedOnEdgeLength(0.9), reg.CorrespondenceCheckerBasedOnDistance(1.5 * v)],
            reg.RANSACConvergenceCriteria(100000, 0.999))
    else:
        result = reg.registration_fgr_based_on_feature_matching(
            source, target, source_fpfh, target_fpfh,
            reg.FastGlobalRegistrationOption(maximum_correspondence_distance=0.5 * v))
    matching_s = time.perf_counter() - t

    print(json.dumps({
        "transform": np.asarray(result.transformation).reshape(-1).tolist(),
        "seconds": time.perf_counter() - start,
        "read_s": read_s,
        "stages": {"features": features_s, "matching": matching_s},
        "source_points": len(source.points),
        "target_points": len(target.points),
        "fitness": result.fitness,
        "inlier_rmse": result.inlier_rmse,
    }))


if __name__ == "__main__":
    main()
