"""Microseconds per configuration of ``indices_at_poses`` on lower-mobility mechanisms against the 8-leg hexapod.

Usage: python benchmarks/bench_lower_mobility.py [--count 20000] [--repeat 3] [--json FILE]

For ``ups_hexapod_8``, ``prs_3_ups``, ``delta_4`` and ``schoenflies_5``, in one process: ``--count`` random
reachable poses about the reference assembly (seeded: +-0.05 length scales, +-0.1 rad), each mechanism's whole
``indices_at_poses`` (closure, screws, every index; one thread) and its closure alone (``solve``), CPU time, best of
``--repeat`` runs, interleaved mechanism by mechanism; printed per configuration with the ratio of the whole to the
hexapod's (issue 28's target: at most 1.3). Kernels are compiled (and the mechanisms loaded) beforehand. Only the
public API is used, so the same script measures an older checkout (``PYTHONPATH=/path/to/old python ...``).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from screwkit.closure import solve
from screwkit.io.loader import load
from screwkit.studies import indices_at_poses

MECHANISMS = ("ups_hexapod_8", "prs_3_ups", "delta_4", "schoenflies_5")


def random_reachable_poses(mechanism, count: int, seed: int = 11) -> np.ndarray:
    """``count`` reachable poses drawn uniformly about the reference assembly (seeded)."""
    rng = np.random.default_rng(seed)
    home = mechanism.home_pose
    span = np.array([0.05 * mechanism.length_scale if name in ("x", "y", "z") else 0.1
                     for name in mechanism.task_coordinates])
    found: list[np.ndarray] = []
    while sum(len(part) for part in found) < count:
        poses = home + rng.uniform(-1.0, 1.0, (4 * count, home.size)) * span
        found.append(poses[solve(mechanism, poses).reachable])
    return np.concatenate(found)[:count]


def seconds(function, *args, **options) -> float:
    """CPU seconds of this process (one thread: the work itself, less of whatever else shares the machine)."""
    start = time.process_time()
    function(*args, **options)
    return time.process_time() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=20_000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", type=Path, help="also write the ratios to the hexapod to this file")
    args = parser.parse_args()
    mechanisms = {name: load(name) for name in MECHANISMS}
    poses = {name: random_reachable_poses(mechanism, args.count) for name, mechanism in mechanisms.items()}
    for name, mechanism in mechanisms.items():  # compile or load every kernel first
        indices_at_poses(mechanism, poses[name][:1024], threads=1)
    whole = {name: np.inf for name in MECHANISMS}
    closure = dict(whole)
    for _ in range(args.repeat):  # interleaved, so that a slow moment of the machine hits every mechanism
        for name, mechanism in mechanisms.items():
            whole[name] = min(whole[name], seconds(indices_at_poses, mechanism, poses[name], threads=1))
            closure[name] = min(closure[name], seconds(solve, mechanism, poses[name]))
    per = {name: 1e6 / args.count for name in MECHANISMS}
    hexapod = whole[MECHANISMS[0]] * per[MECHANISMS[0]]
    print(f"{args.count} random reachable poses each, one thread, CPU time, best of {args.repeat}, "
          "us per configuration")
    print(f"{'mechanism':15s} {'n':>2s} {'closure':>8s} {'rest':>7s} {'total':>7s}  ratio to {MECHANISMS[0]}")
    for name, mechanism in mechanisms.items():
        total = whole[name] * per[name]
        solving = closure[name] * per[name]
        print(f"{name:15s} {mechanism.dof:2d} {solving:8.1f} {total - solving:7.1f} {total:7.1f}  "
              f"{total / hexapod:.2f}")
    if args.json:
        args.json.write_text(json.dumps({name: {"microseconds": whole[name] * per[name],
                                                "ratio": whole[name] * per[name] / hexapod} for name in MECHANISMS}))


if __name__ == "__main__":
    main()
