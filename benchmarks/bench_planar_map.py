"""The paper's Fig. 5 map command against the straightforward numpy script, side by side, as whole processes.

Usage: python benchmarks/bench_planar_map.py [--radius 0.6] [--step 0.02] [--phi-step 1] [--repeat 3] [--json FILE]

Runs, in turn, ``screwkit map planar_5rrr --radius R --step S --phi-step D`` and
``python benchmarks/reference_planar_map.py --radius R --step S --phi-step D`` (``--repeat`` pairs, after
one unmeasured run of each), each as a new process: wall time, CPU time and peak resident memory from the
operating system (``os.wait4``). Prints the medians, the ratio command / script pair by pair (median, min,
max), the fixed cost of each (the same commands on the 5 grid points of a disc of one step, 3 orientations),
the largest difference between the two maps (every index both write, where both are finite, and whether
they are NaN at the same grid points), and whether the targets of issue 28 are met as measured here: the
command <= 0.8 s, <= 0.35 of the script's wall time, its peak memory <= 1.5 x the script's.
The defaults are the paper's map: 2,821 grid points x 360 orientations, 1,015,560 configurations.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
from pathlib import Path

import numpy as np
from bench_hexapod_map import measured_maps, print_ratios  # the same measurement, side by side

HERE = Path(__file__).resolve().parent
TARGET_WALL = 0.8
TARGET_RATIO = 0.35
TARGET_MEMORY = 1.5


def commands(radius: float, step: float, phi_step: float, folder: Path) -> tuple[list[str], list[str]]:
    area = ["--radius", str(radius), "--step", str(step), "--phi-step", str(phi_step)]
    command = [sys.executable, "-m", "screwkit.cli", "map", "planar_5rrr", *area, "--quiet", "--overwrite",
               "--out", str(folder / "map.nc")]
    script = [sys.executable, str(HERE / "reference_planar_map.py"), *area, "--out", str(folder / "reference.npz")]
    return command, script


def met(value: float, limit: float) -> str:
    return "met" if value <= limit else "not met"


def compare(reference, mapped) -> tuple[list[str], list[str], float, bool, int]:
    """The variables both maps have, those only one has, their largest difference where both are finite, whether
    they are NaN at the same points, and the grid points reached."""
    names = [name for name in mapped.data_vars if name in reference.files]
    missing = sorted(set(mapped.data_vars) ^ (set(reference.files) - {"x", "y"}))
    difference, same_nan = 0.0, True
    for name in names:
        ours, theirs = mapped[name].values, reference[name]
        same_nan &= bool(np.array_equal(np.isnan(ours), np.isnan(theirs)))
        finite = np.isfinite(ours) & np.isfinite(theirs)
        if finite.any():
            difference = max(difference, float(np.max(np.abs(ours[finite] - theirs[finite]))))
    return names, missing, difference, same_nan, int(np.isfinite(mapped["reachable_fraction"].values).sum())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--radius", type=float, default=0.6)
    parser.add_argument("--step", type=float, default=0.02)
    parser.add_argument("--phi-step", type=float, default=1.0)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", type=Path, help="also write the measures of issue 28's targets to this file")
    args = parser.parse_args()
    load_before = os.getloadavg()
    runs, fixed, (names, missing, difference, same_nan, points) = measured_maps(
        commands, (args.radius, args.step, args.phi_step), (args.step, args.step, 120.0), args.repeat, compare)
    orientations = len(np.arange(0.0, 360.0 - 1e-9, args.phi_step))
    load_after = os.getloadavg()
    print(f"planar_5rrr map (Fig. 5), disc of radius {args.radius:g} m, step {args.step:g} m, phi step "
          f"{args.phi_step:g} deg: {points:,} grid points x {orientations} orientations = "
          f"{points * orientations:,} configurations; {args.repeat} pairs, medians; load average "
          f"{load_before[0]:.1f} before, {load_after[0]:.1f} after ({os.cpu_count()} cores)")
    print(f"{'':10s} {'wall s':>8s} {'CPU s':>8s} {'peak MiB':>9s}   fixed cost (5 grid points, 3 orientations): "
          "wall, CPU, peak")
    medians = {}
    for name in ("command", "script"):
        medians[name] = wall, cpu, peak = [statistics.median(values) for values in zip(*runs[name])]
        print(f"{name:10s} {wall:8.2f} {cpu:8.2f} {peak:9.0f}   {fixed[name][0]:.2f} s, {fixed[name][1]:.2f} s, "
              f"{fixed[name][2]:.0f} MiB")
    ratios = print_ratios(runs)
    memory = medians["command"][2] / medians["script"][2]
    print(f"peak memory, command / script: {memory:.2f} ({medians['command'][2]:.0f} against "
          f"{medians['script'][2]:.0f} MiB)")
    print(f"largest difference between the two maps ({', '.join(names)}; where both are finite): {difference:.1e}; "
          f"NaN at the same grid points: {'yes' if same_nan else 'no'}"
          + (f"; written by one only: {', '.join(missing)}" if missing else ""))
    print("issue 28's targets, as measured in this run:")
    print(f"  command <= {TARGET_WALL} s wall: {medians['command'][0]:.2f} s (CPU {medians['command'][1]:.2f} s): "
          f"{met(medians['command'][0], TARGET_WALL)}")
    print(f"  command <= {TARGET_RATIO} of the script's wall time: {statistics.median(ratios['wall']):.3f} "
          f"(CPU {statistics.median(ratios['CPU']):.3f}): {met(statistics.median(ratios['wall']), TARGET_RATIO)}")
    print(f"  peak memory <= {TARGET_MEMORY} x the script's: {memory:.2f} x: {met(memory, TARGET_MEMORY)}")
    if args.json:
        args.json.write_text(json.dumps({
            "configurations": points * orientations, "command_wall_s": medians["command"][0],
            "script_wall_s": medians["script"][0], "ratio_wall": statistics.median(ratios["wall"]),
            "ratio_cpu": statistics.median(ratios["CPU"]), "memory_ratio": memory, "difference": difference}))


if __name__ == "__main__":
    main()
