"""Wall time of the full workspace-map command, against a per-configuration loop.

Usage: python benchmarks/bench_map.py [--large] [--repeat 3] [--loop-samples 300]

1. ``screwkit map planar_5rrr --radius 0.6 --step 0.02 --phi-step 1`` (about 2,800 positions x
   360 angles, 10^6 configurations, closure solving included) as a subprocess, timed from
   start to exit, through the generic URDF path and through the planar closed forms; peak
   resident memory of the command. Each command runs ``--repeat`` times, interleaved; the
   median and the best run are printed (this shared machine is noisy).
   The fixed cost of the same command on a 15-configuration map (interpreter, imports,
   URDF loading, compiled-kernel cache, output file) and of importing numpy, numba,
   Pinocchio and Dask alone are measured the same way.
2. With ``--large``: the same map at 0.1 deg steps (10^7 configurations), to show that memory
   stays constant (the work is chunked).
3. A straightforward per-configuration loop, as a user would write it by hand: for each pose
   ``solve_one`` (closure), Pinocchio ``computeJointJacobians``, ``chain_screws`` and
   ``analyze`` on that single configuration; its rate is measured on ``--loop-samples``
   poses and compared with the batched generic path's rate in the same run.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np


def run_command(arguments: list[str]) -> tuple[float, float]:
    """Wall time (s) and peak resident memory (MB) of one screwkit command in a subprocess."""
    return run_process([sys.executable, "-m", "screwkit.cli", *arguments])


def run_process(command: list[str]) -> tuple[float, float]:
    """Wall time (s) and peak resident memory (MB) of a subprocess."""
    start = time.perf_counter()
    with subprocess.Popen(command) as process:
        _, status, usage = os.wait4(process.pid, 0)
        process.returncode = os.waitstatus_to_exitcode(status)
    elapsed = time.perf_counter() - start
    if process.returncode:
        raise subprocess.CalledProcessError(process.returncode, command)
    return elapsed, usage.ru_maxrss / 1024


def per_configuration_rate(samples: int) -> float:
    import pinocchio

    from screwkit.closure import chain_screws, solve_one
    from screwkit.indices.analysis import analyze
    from screwkit.io.loader import load
    from screwkit.model.pinocchio_bridge import configuration_vector

    mechanism = load("planar_5rrr")
    data = mechanism.pinocchio_model.createData()
    rng = np.random.default_rng(0)
    radius = 0.6 * np.sqrt(rng.uniform(0, 1, samples))
    angle = rng.uniform(0, 2 * np.pi, samples)
    poses = np.column_stack([radius * np.cos(angle), radius * np.sin(angle), rng.uniform(0, 2 * np.pi, samples)])
    analyze(chain_screws(mechanism, solve_one(mechanism, poses[0])))  # warm up
    start = time.perf_counter()
    done = 0
    for pose in poses:
        try:
            solution = solve_one(mechanism, pose)
        except ValueError:
            continue
        q = configuration_vector(mechanism, solution.joint_values, solution.full_poses)
        pinocchio.computeJointJacobians(mechanism.pinocchio_model, data, q)
        analyze(chain_screws(mechanism, solution), threads=1)
        done += 1
    return len(poses) / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--large", action="store_true", help="also run the 10^7-configuration map")
    parser.add_argument("--repeat", type=int, default=3, help="runs of each command (median and best shown)")
    parser.add_argument("--loop-samples", type=int, default=300)
    args = parser.parse_args()
    folder = tempfile.mkdtemp()
    out = os.path.join(folder, "map.nc")
    common = ["map", "planar_5rrr", "--out", out, "--overwrite", "--quiet"]
    full = ["--radius", "0.6", "--step", "0.02", "--phi-step", "1"]
    tiny = ["--radius", "0.02", "--step", "0.02", "--phi-step", "120"]  # 5 positions x 3 angles
    run_command(common + full[:4] + ["--phi-step", "30"])  # warm the compiled-kernel caches
    run_command(common + full[:4] + ["--phi-step", "30", "--closed-forms"])
    commands = {
        "generic URDF path": [sys.executable, "-m", "screwkit.cli", *common, *full],
        "planar closed forms": [sys.executable, "-m", "screwkit.cli", *common, *full, "--closed-forms"],
        "fixed cost, generic (15 configurations)": [sys.executable, "-m", "screwkit.cli", *common, *tiny],
        "fixed cost, closed forms (15 configurations)": [sys.executable, "-m", "screwkit.cli", *common, *tiny,
                                                         "--closed-forms"],
        "import numpy, numba, pinocchio, dask": [sys.executable, "-c", "import numpy, numba, pinocchio, dask"],
    }
    full_maps = ("generic URDF path", "planar closed forms")
    runs = {name: [] for name in commands}
    for _ in range(args.repeat):
        for name, command in commands.items():
            runs[name].append(run_process(command))
    configurations = 2821 * 360
    print(f"map 0.6 m / 0.02 m / 1 deg ({configurations:,} configurations), whole command, wall "
          f"(median and best of {args.repeat}):")
    for name, measured in runs.items():
        times = np.array([t for t, _ in measured])
        memory = max(m for _, m in measured)
        rate = f"  ({configurations / np.median(times):,.0f} configurations/s)" if name in full_maps else ""
        print(f"  {name:<45s} {np.median(times):6.2f} s  best {times.min():6.2f} s  peak memory {memory:,.0f} MB{rate}")
    generic = float(np.median([t for t, _ in runs["generic URDF path"]]))
    loop = per_configuration_rate(args.loop_samples)
    print(f"per-configuration loop (solve_one + Pinocchio Jacobians + chain_screws + analyze): "
          f"{loop:,.0f} configurations/s")
    print(f"batched generic command / per-configuration loop: {configurations / generic / loop:,.0f}x")
    if args.large:
        large, large_memory = run_command(common + ["--radius", "0.6", "--step", "0.02", "--phi-step", "0.1"])
        print(f"  10^7 configurations (0.1 deg): {large:6.1f} s, peak memory {large_memory:,.0f} MB")


if __name__ == "__main__":
    main()
