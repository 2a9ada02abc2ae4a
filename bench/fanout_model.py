#!/usr/bin/env python3
"""Wall time of an all-pairs project across replicas, from measured per-stage costs (bench/fanout.sh).

    wall(N, R) = N * read_s                                   scans read once, on the coordinator
               + ceil(P / (R * workers)) * pair_s              pair jobs, P = N (N - 1) / 2, spread evenly
               + P * scans_sent * scan_bytes / egress         the scans leave the coordinator (its NIC): peers keep
                                                              the scans they were sent, so a pair sends 0-2 of them
               + global_s(N)                                  loop checks, selection, refinement (coordinator)

The pair and transfer terms overlap in practice (the coordinator sends while peers compute), so the model takes
the larger of the two rather than their sum. global_s is fitted as c * N^3 through the measured point (the loop
checks go over the triangles of the pair graph: conservative for the refinement, which grows more slowly).

    bench/fanout_model.py --pair-s 14.2 --read-s 0.025 --global-s 0.007 --global-n 10 --pair-mb 22.4 --scans-sent 1
"""
import argparse
import math


def wall_s(n, replicas, a):
    pairs = n * (n - 1) // 2
    compute = math.ceil(pairs / (replicas * a.workers)) * a.pair_s
    transfer = pairs * a.scans_sent * a.pair_mb / 2 * 1e6 / (a.egress_gbit * 1e9 / 8) if replicas > 1 else 0.0
    return n * a.read_s + max(compute, transfer) + a.global_s * (n / a.global_n) ** 3, compute, transfer


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--pair-s", type=float, required=True, help="median seconds per pair job on one core")
    p.add_argument("--read-s", type=float, required=True, help="seconds to read one scan on the coordinator")
    p.add_argument("--global-s", type=float, required=True, help="selection + refinement seconds at --global-n scans")
    p.add_argument("--global-n", type=int, required=True)
    p.add_argument("--pair-mb", type=float, required=True, help="bytes of one pair job, MB")
    p.add_argument("--workers", type=int, default=2, help="pair workers per replica (2-core pods: 2)")
    p.add_argument("--scans-sent", type=float, default=2.0,
                   help="scans sent per pair: 2 without the peers' scan cache, about 1 when it holds a few scans")
    p.add_argument("--egress-gbit", type=float, default=10.0, help="the coordinator's network, Gbit/s")
    a = p.parse_args()
    print(f"| scans | pairs | " + " | ".join(f"{r} replica{'s' if r > 1 else ''}" for r in (1, 4, 16, 64)) + " |")
    print("|---:|---:|" + "---:|" * 4)
    for n in (50, 200):
        cells = []
        for r in (1, 4, 16, 64):
            total, compute, transfer = wall_s(n, r, a)
            bound = " (network-bound)" if transfer > compute else ""
            cells.append(f"{total / 3600:.2f} h{bound}" if total >= 3600 else f"{total / 60:.1f} min{bound}")
        print(f"| {n} | {n * (n - 1) // 2} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
