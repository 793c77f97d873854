"""Configurations per second of the index computation on the paper's 5-RRR.

Usage: python benchmarks/bench_core.py [--configurations 1000000] [--batch 200000]

Screws are built from random reachable poses beforehand (closure solving excluded, as the
benchmark measures the index computation); both paths see the same configurations, in
batches so that memory stays bounded. Prints the rate of the generic screw path, of the
planar closed forms, their ratio, and the peak resident memory of the process.
"""

from __future__ import annotations

import argparse
import resource
import time

import numpy as np

from screwkit.indices.analysis import analyze
from screwkit.indices.closed_forms import planar_indices
from screwkit.screw.planar import paper_5rrr, planar_joint_points, rrr_chain_screws


def reachable_points(rng, count, design):
    """Joint points of `count` random reachable poses in a disc of radius 0.5 m, any angle."""
    radius = 0.5 * np.sqrt(rng.uniform(0, 1, count))
    angle = rng.uniform(0, 2 * np.pi, count)
    poses = np.column_stack([radius * np.cos(angle), radius * np.sin(angle), rng.uniform(0, 2 * np.pi, count)])
    base, elbows, distal, ok = planar_joint_points(design, poses)
    return base[ok], elbows[ok], distal[ok]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--configurations", type=int, default=1_000_000)
    parser.add_argument("--batch", type=int, default=100_000)
    parser.add_argument("--threads", type=int, default=None)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    design = paper_5rrr()
    warm = reachable_points(rng, 1000, design)  # compile / warm up outside the timing
    analyze(rrr_chain_screws(*warm), detail=False)
    planar_indices(*warm)
    generic_time = closed_time = 0.0
    done = 0
    worst = 0.0
    while done < args.configurations:
        base, elbows, distal = reachable_points(rng, min(args.batch, args.configurations - done) + 64, design)
        base, elbows, distal = (a[: args.configurations - done] for a in (base, elbows, distal))
        chains = rrr_chain_screws(base, elbows, distal)
        start = time.perf_counter()
        generic = analyze(chains, detail=False, threads=args.threads)
        generic_time += time.perf_counter() - start
        start = time.perf_counter()
        closed = planar_indices(base, elbows, distal, threads=args.threads)
        closed_time += time.perf_counter() - start
        worst = max(worst, float(np.abs(generic.f_o[1] - closed["f_o"][1]).max()))
        done += len(base)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"configurations: {done:,} of the 5-RRR (Table 2), random reachable poses")
    print(f"generic screw path : {done / generic_time:12,.0f} configurations/s  ({generic_time:.2f} s)")
    print(f"planar closed forms: {done / closed_time:12,.0f} configurations/s  ({closed_time:.2f} s)")
    print(f"closed forms / generic: {generic_time / closed_time:.2f}x")
    print(f"largest |F_O1 generic - closed form|: {worst:.1e}")
    print(f"peak resident memory: {peak:,.0f} MB")


if __name__ == "__main__":
    main()
