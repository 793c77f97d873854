"""Microseconds per configuration of lower-mobility mechanisms against the 8-leg hexapod, stage by stage.

Usage: python benchmarks/bench_mobility.py [--repeat 3]

For each bundled lower-mobility mechanism and for ``ups_hexapod_8``, a grid of about 14,000 task
poses around the reference assembly is closed (``solve``: the dependent coordinates and every
chain), its joint screws built (``chain_screws``) and every index computed (``analyze_solution``),
on one thread; the best of ``--repeat`` runs of each stage is printed per configuration, with the
ratio of the whole to the hexapod's. Kernels are compiled (and the mechanisms loaded) beforehand.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from screwkit.closure import chain_screws, solve
from screwkit.closure.threads import thread_limit
from screwkit.io.loader import load
from screwkit.studies.poses import analyze_solution

MECHANISMS = ("ups_hexapod_8", "prs_3_ups", "delta_4", "schoenflies_5")


def grid(mechanism, per_axis: int) -> np.ndarray:
    """Task poses on a grid around the reference assembly: +-0.3 rad, +-0.1 length scales."""
    home = mechanism.task_poses(mechanism.home_full_pose)
    spread = np.where(mechanism.angular, 0.3, 0.1 * mechanism.length_scale)
    axes = [np.linspace(-1.0, 1.0, per_axis) * s + h for h, s in zip(home, spread)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, mechanism.n_task)


def best(function, repeat: int) -> tuple[float, object]:
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return min(times), result


def stage_times(mechanism, poses: np.ndarray, repeat: int) -> tuple[float, float, float, object]:
    """Best times (s) of closing, building screws and computing every index (screws included), one thread."""
    with thread_limit(1):
        warm = solve(mechanism, poses[:20])
        analyze_solution(mechanism, warm, unreachable="drop", threads=1)
        t_solve, solution = best(lambda: solve(mechanism, poses), repeat)
        t_screws, _ = best(lambda: chain_screws(mechanism, solution, unreachable="drop"), repeat)
        t_all, _ = best(lambda: analyze_solution(mechanism, solution, unreachable="drop", threads=1), repeat)
    return t_solve, t_screws, t_all, solution


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    rows = []
    for name in MECHANISMS:
        mechanism = load(name)
        poses = grid(mechanism, int(round(14_000 ** (1.0 / mechanism.n_task))))
        t_solve, t_screws, t_all, solution = stage_times(mechanism, poses, args.repeat)
        count = poses.shape[0]
        reachable = int(np.sum(solution.reachable))
        rows.append((name, mechanism.n_task, count, reachable, t_solve / count * 1e6, t_screws / count * 1e6,
                     (t_all - t_screws) / count * 1e6, (t_solve + t_all) / count * 1e6))
    hexapod = rows[0][-1]
    print(f"{'mechanism':15s} {'n':>2s} {'configs':>8s} {'reach':>6s} {'closure':>8s} {'screws':>7s} "
          f"{'indices':>8s} {'total':>7s}  ratio to {MECHANISMS[0]} (us per configuration, one thread)")
    for name, n, count, reachable, closure, screws, indices, total in rows:
        print(f"{name:15s} {n:2d} {count:8d} {reachable:6d} {closure:8.1f} {screws:7.1f} {indices:8.1f} {total:7.1f}"
              f"  {total / hexapod:.2f}")


if __name__ == "__main__":
    main()
