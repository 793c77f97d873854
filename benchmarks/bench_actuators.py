"""How the cost per configuration grows with the number of actuators a, and what the compile costs.

Usage: python benchmarks/bench_actuators.py [--poses 4000] [--repeat 3] [--compile]

Mechanisms, generated here through the library's URDF writer and loaded like any file:
- a-UPS hexapods (6 DOF), a = 7..14: the bundled 8-UPS geometry with a legs, each leg to a
  platform slot of one fixed random permutation (seed 0);
- planar n-RRR (3 DOF), a = 4..10: base joints on a 0.7 m circle, platform joints on a 0.2 m
  circle in reversed order, arms 0.5 m (no leg stretched straight at the reference assembly);
- the bundled ``coop_arms`` (two 6-joint arms holding one object: a = 12, 6 DOF).

For each, ``--poses`` random poses near the reference assembly are closed and their screws built
once; then, on one thread, best of ``--repeat``: ``closure + screws`` (``solve`` and
``chain_screws``) and ``indices`` (``transmission.analyze``, detail off) for every j
(``all j``) and for j = 1 only. Columns: submechanisms C(a, n), sets of n - 1 locked actuators
C(a, n - 1) (one output twist each), the sets E of the fault reductions over every j, and
microseconds per configuration. With ``--compile``, every kernel is also compiled from an empty
numba cache (``screwkit warmup`` in a new process with its own ``NUMBA_CACHE_DIR``), and the time
of each printed.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from math import comb
from pathlib import Path

import numpy as np

from screwkit.closure import chain_screws, solve
from screwkit.closure.threads import thread_limit
from screwkit.indices.analysis import analyze
from screwkit.io.loader import load
from screwkit.model.urdf_writer import planar_rrr_urdf
from screwkit.robots.generate import UPS_HEXAPOD, ups_hexapod


def hexapod_file(folder: Path, legs: int) -> Path:
    slots = tuple(int(s) for s in np.random.default_rng(0).permutation(legs))
    path = folder / f"ups_hexapod_{legs}.urdf"
    path.write_text(ups_hexapod({**UPS_HEXAPOD, "legs": legs, "platform_slots": slots}, path.stem))
    return path


def planar_file(folder: Path, legs: int) -> Path:
    angles = 2 * np.pi * np.arange(legs) / legs
    base = 0.7 * np.column_stack([np.cos(angles), np.sin(angles)])
    platform = 0.2 * np.column_stack([np.cos(-angles), np.sin(-angles)])
    path = folder / f"planar_{legs}rrr.urdf"
    path.write_text(planar_rrr_urdf(path.stem, base, platform, 0.5, 0.5))
    return path


def random_poses(mechanism, count: int, seed: int = 1) -> np.ndarray:
    """Poses about the reference assembly: +-0.05 length scales, +-5 deg."""
    rng = np.random.default_rng(seed)
    home = mechanism.task_poses(mechanism.home_full_pose)
    spread = np.where(mechanism.angular, np.deg2rad(5.0), 0.05 * mechanism.length_scale)
    return home + rng.uniform(-1.0, 1.0, (count, mechanism.n_task)) * spread


def best(function, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def row(label: str, mechanism, poses: np.ndarray, repeat: int) -> str:
    a, n = len(mechanism.actuators), mechanism.dof
    if n != mechanism.n_task:
        raise SystemExit(f"{label}: {n} DOF at the reference assembly, expected {mechanism.n_task} (a singular design)")
    with thread_limit(1):
        solution = solve(mechanism, poses)
        screws = chain_screws(mechanism, solution, unreachable="drop")
        count = int(np.sum(solution.reachable))
        analyze(screws, detail=False, threads=1)  # compiled and warm
        closure = best(lambda: chain_screws(mechanism, solve(mechanism, poses), unreachable="drop"), repeat)
        every = best(lambda: analyze(screws, detail=False, threads=1), repeat)
        first = best(lambda: analyze(screws, faults=1, detail=False, threads=1), repeat)
    sets = sum(comb(a, j) for j in range(1, a - n + 1))
    return (f"{label:16s} {a:3d} {n:2d} {comb(a, n):6d} {comb(a, n - 1):6d} {sets:7d} {count:6d} "
            f"{closure / poses.shape[0] * 1e6:9.1f} {every / count * 1e6:9.1f} {first / count * 1e6:9.1f}")


def compile_times() -> None:
    """``screwkit warmup`` from an empty numba cache, in a new process."""
    with tempfile.TemporaryDirectory() as cache:
        start = time.perf_counter()
        done = subprocess.run([sys.executable, "-m", "screwkit.cli", "warmup"], capture_output=True, text=True,
                              env={**os.environ, "NUMBA_CACHE_DIR": cache}, check=True)
        total = time.perf_counter() - start
    print("compile from an empty cache (screwkit warmup):")
    print("  " + done.stderr.strip().replace("\n", "\n  "))
    print(f"  whole command: {total:.1f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=4000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--compile", action="store_true", help="also time every kernel's compilation")
    args = parser.parse_args()
    print(f"{'mechanism':16s} {'a':>3s} {'n':>2s} {'C(a,n)':>6s} {'C(a,n-1)':>6s} {'sets E':>7s} {'reach':>6s} "
          f"{'closure':>9s} {'all j':>9s} {'j = 1':>9s}   (us per configuration, one thread)")
    with tempfile.TemporaryDirectory() as folder:
        for legs in range(4, 11):
            mechanism = load(planar_file(Path(folder), legs))
            print(row(mechanism.name, mechanism, random_poses(mechanism, args.poses), args.repeat), flush=True)
        for legs in range(7, 15):
            mechanism = load(hexapod_file(Path(folder), legs))
            count = args.poses if legs <= 11 else max(args.poses // 4, 100)
            print(row(mechanism.name, mechanism, random_poses(mechanism, count), args.repeat), flush=True)
    coop = load("coop_arms")
    print(row("coop_arms", coop, random_poses(coop, max(args.poses // 4, 100)), args.repeat), flush=True)
    if args.compile:
        compile_times()


if __name__ == "__main__":
    main()
