#!/usr/bin/python3
"""Open3D's multiway registration recipe on a project of scans: the peer of `k4reg align-project` in
bench/RESULTS.md (run by bench/project_vs_open3d.sh).

    open3d_project.py --voxel V --out result.json SCAN1.ply SCAN2.ply ...

The recipe of Open3D's tutorials (global registration + multiway registration), every parameter scaled from one
voxel size V (the project's sigma, what k4reg gets as --min-scale):
  - each scan: voxel_down_sample(V); normals, KDTreeSearchParamHybrid(2 V, 30); FPFH, KDTreeSearchParamHybrid(5 V, 100)
  - every pair (i < j), source i, target j:
      RANSAC on FPFH matches (mutual filter, distance 1.5 V, point-to-point, ransac_n 3, checkers edge length 0.9
      and distance 1.5 V, RANSACConvergenceCriteria(100000, 0.999)),
      then point-to-plane ICP from the RANSAC pose, coarse at 15 V, fine at 1.5 V,
      information matrix get_information_matrix_from_point_clouds(..., 1.5 V, T_fine)
  - pose graph: odometry edges j = i + 1 (certain; they also give the initial node poses), every other pair a
    loop-closure edge (uncertain)
  - global_optimization: GlobalOptimizationLevenbergMarquardt, GlobalOptimizationConvergenceCriteria(),
    GlobalOptimizationOption(max_correspondence_distance=1.5 V, edge_prune_threshold=0.25, reference_node=0)
  - o3d.utility.random.seed(1), so runs repeat.

Writes {"scans": [{"file", "pose": 16 numbers row-major, p_project = pose * p_scan}], "seconds", "stages", "pairs"}
("pairs": each pair's RANSAC and ICP fitness and inlier RMSE and its ICP transform, source -> target),
the first scan being the reference (identity).
"""
import argparse
import json
import time

import numpy as np
import open3d as o3d

reg = o3d.pipelines.registration


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--voxel", type=float, required=True, help="voxel size V, in the files' units")
    ap.add_argument("--out", required=True, help="result JSON")
    ap.add_argument("scans", nargs="+")
    a = ap.parse_args()
    v = a.voxel
    o3d.utility.random.seed(1)
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    stages = dict.fromkeys(["read", "preprocess", "ransac", "icp", "information", "global_optimization"], 0.0)
    start = time.perf_counter()

    def timed(stage, f, *args):
        t = time.perf_counter()
        r = f(*args)
        stages[stage] += time.perf_counter() - t
        return r

    def preprocess(path):
        pcd = timed("read", o3d.io.read_point_cloud, path)
        t = time.perf_counter()
        down = pcd.voxel_down_sample(v)
        down.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=2 * v, max_nn=30))
        fpfh = reg.compute_fpfh_feature(down, o3d.geometry.KDTreeSearchParamHybrid(radius=5 * v, max_nn=100))
        stages["preprocess"] += time.perf_counter() - t
        return down, fpfh

    clouds = [preprocess(p) for p in a.scans]
    graph = reg.PoseGraph()
    graph.nodes.append(reg.PoseGraphNode(np.identity(4)))
    odometry = np.identity(4)
    pairs = []
    point_to_plane = reg.TransformationEstimationPointToPlane()
    for i in range(len(clouds)):
        for j in range(i + 1, len(clouds)):
            (src, src_f), (tgt, tgt_f) = clouds[i], clouds[j]
            ransac = timed("ransac", reg.registration_ransac_based_on_feature_matching, src, tgt, src_f, tgt_f, True,
                           1.5 * v, reg.TransformationEstimationPointToPoint(False), 3,
                           [reg.CorrespondenceCheckerBasedOnEdgeLength(0.9),
                            reg.CorrespondenceCheckerBasedOnDistance(1.5 * v)],
                           reg.RANSACConvergenceCriteria(100000, 0.999))
            coarse = timed("icp", reg.registration_icp, src, tgt, 15 * v, ransac.transformation, point_to_plane)
            fine = timed("icp", reg.registration_icp, src, tgt, 1.5 * v, coarse.transformation, point_to_plane)
            info = timed("information", reg.get_information_matrix_from_point_clouds, src, tgt, 1.5 * v,
                         fine.transformation)
            if j == i + 1:  # odometry: chains the initial poses
                odometry = fine.transformation @ odometry
                graph.nodes.append(reg.PoseGraphNode(np.linalg.inv(odometry)))
            graph.edges.append(reg.PoseGraphEdge(i, j, fine.transformation, info, uncertain=j != i + 1))
            pairs.append({"source": i, "target": j, "ransac_fitness": ransac.fitness, "ransac_rmse": ransac.inlier_rmse,
                          "icp_fitness": fine.fitness, "icp_rmse": fine.inlier_rmse,
                          "transform": fine.transformation.flatten().tolist()})  # source -> target
    option = reg.GlobalOptimizationOption(max_correspondence_distance=1.5 * v, edge_prune_threshold=0.25,
                                          reference_node=0)
    timed("global_optimization", reg.global_optimization, graph, reg.GlobalOptimizationLevenbergMarquardt(),
          reg.GlobalOptimizationConvergenceCriteria(), option)
    to_reference = np.linalg.inv(graph.nodes[0].pose)  # identity already; kept for clarity
    result = {
        "scans": [{"file": p, "pose": (to_reference @ n.pose).flatten().tolist()} for p, n in zip(a.scans, graph.nodes)],
        "seconds": time.perf_counter() - start,
        "stages": stages,
        "pairs": pairs,
        "open3d": o3d.__version__,
        "voxel": v,
    }
    with open(a.out, "w") as f:
        json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
