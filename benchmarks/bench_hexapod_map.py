"""The hexapod map command against the straightforward numpy script, side by side, as whole processes.

Usage: python benchmarks/bench_hexapod_map.py [--step 0.005] [--half 0.1] [--yaw-step 1] [--repeat 3] [--json FILE]

Runs, in turn, ``screwkit map ups_hexapod_8 --grid x:-H:H:S --grid y:-H:H:S --over yaw:0:360:D
--ignore-limits`` and ``python benchmarks/reference_hexapod_map.py --step S --half H --yaw-step D``
(``--repeat`` pairs, after one unmeasured run of each), each as a new process: wall time, CPU time
and peak resident memory from the operating system (``os.wait4``). Prints the medians, the ratio
command / script pair by pair (median, min, max), the fixed cost of each (the same commands on a
3 x 3 grid with 3 yaws), the command's peak memory against the script's plus the difference in
fixed cost, and the largest difference between the two maps (LMTI, F_O1, F_O2).
The defaults are the 41 x 41 grid and full turn at 1 deg: 605,160 configurations.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def commands(step: float, half: float, yaw_step: float, folder: Path) -> tuple[list[str], list[str]]:
    grid = [f"x:{-half}:{half}:{step}", f"y:{-half}:{half}:{step}"]
    command = [sys.executable, "-m", "screwkit.cli", "map", "ups_hexapod_8", "--grid", grid[0], "--grid", grid[1],
               "--over", f"yaw:0:360:{yaw_step}", "--ignore-limits", "--quiet", "--overwrite",
               "--out", str(folder / "map.nc")]
    script = [sys.executable, str(HERE / "reference_hexapod_map.py"), "--step", str(step), "--half", str(half),
              "--yaw-step", str(yaw_step), "--out", str(folder / "reference.npz")]
    return command, script


def measured(arguments: list[str]) -> tuple[float, float, float]:
    """Wall (s), CPU (s) and peak resident memory (MiB) of one run of a new process."""
    start = time.perf_counter()
    process = subprocess.Popen(arguments, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - start
    errors = process.stderr.read().decode()
    process.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{' '.join(arguments)} failed:\n{errors}")
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024


def side_by_side(command: list[str], script: list[str], small_command: list[str], small_script: list[str],
                 repeat: int) -> tuple[dict, dict]:
    """The command and the script run in turn ``repeat`` times, after one unmeasured run of each (compiled kernels,
    warm file cache), then each once on its small case: ``measured`` figures by name, and the fixed costs."""
    for arguments in (command, script):
        measured(arguments)
    runs = {"command": [], "script": []}
    for _ in range(repeat):
        runs["command"].append(measured(command))
        runs["script"].append(measured(script))
    return runs, {"command": measured(small_command), "script": measured(small_script)}


def measured_maps(commands, large: tuple, small: tuple, repeat: int, compare):
    """``commands(*large, folder)`` and ``commands(*small, folder)`` (the map command and the script, writing
    ``map.nc`` and ``reference.npz`` in ``folder``) measured by :func:`side_by_side` in a temporary folder, and
    ``compare(reference, mapped)`` on the large case's two files before the folder goes: the runs, the fixed
    costs and what ``compare`` returns."""
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        command, script = commands(*large, folder)
        (folder / "small").mkdir()
        small_command, small_script = commands(*small, folder / "small")
        runs, fixed = side_by_side(command, script, small_command, small_script, repeat)
        import xarray  # the map's file: read once both have run

        reference = np.load(folder / "reference.npz")
        with xarray.open_dataset(folder / "map.nc") as mapped:
            return runs, fixed, compare(reference, mapped)


def print_ratios(runs: dict) -> dict[str, list[float]]:
    """The command's wall and CPU times over the script's, pair by pair, printed (median, min, max); returned."""
    ratios = {}
    for index, label in enumerate(("wall", "CPU")):
        ratios[label] = [a[index] / b[index] for a, b in zip(runs["command"], runs["script"])]
        median = statistics.median(ratios[label])
        speed = f"{1 / median:.1f}x faster" if median < 1 else f"{median:.1f}x slower"
        print(f"command / script, {label} (pair by pair): median {median:.3f}, min {min(ratios[label]):.3f}, "
              f"max {max(ratios[label]):.3f}  ({speed})")
    return ratios


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--step", type=float, default=0.005)
    parser.add_argument("--half", type=float, default=0.1)
    parser.add_argument("--yaw-step", type=float, default=1.0)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", type=Path, help="also write the measures of issue 28's targets to this file")
    args = parser.parse_args()
    runs, fixed, difference = measured_maps(
        commands, (args.step, args.half, args.yaw_step), (args.half, args.half, 120.0), args.repeat,
        lambda reference, mapped: max(float(np.nanmax(np.abs(reference[key] - mapped[key].values)))
                                      for key in ("lmti", "f_o1", "f_o2")))
    points = int(round(2 * args.half / args.step)) + 1
    yaws = int(round(360 / args.yaw_step))
    print(f"ups_hexapod_8 map, {points} x {points} grid, {yaws} yaws: {points * points * yaws:,} configurations; "
          f"{args.repeat} pairs, medians")
    print(f"{'':10s} {'wall s':>8s} {'CPU s':>8s} {'peak MiB':>9s}   fixed cost (3 x 3 grid, 3 yaws): wall, peak")
    for name in ("command", "script"):
        wall, cpu, peak = (statistics.median(values) for values in zip(*runs[name]))
        print(f"{name:10s} {wall:8.2f} {cpu:8.2f} {peak:9.0f}   {fixed[name][0]:.2f} s, {fixed[name][2]:.0f} MiB")
    ratios = print_ratios(runs)
    peak = {name: statistics.median(run[2] for run in runs[name]) for name in runs}
    allowed = peak["script"] + fixed["command"][2] - fixed["script"][2]
    print(f"peak memory: command {peak['command']:.0f} MiB; the script's {peak['script']:.0f} MiB plus the difference "
          f"in fixed cost ({fixed['command'][2]:.0f} - {fixed['script'][2]:.0f} MiB) allows {allowed:.0f} MiB: "
          f"{'within' if peak['command'] <= allowed else 'over'}")
    print(f"largest difference between the two maps (LMTI, F_O1, F_O2): {difference:.1e}")
    if args.json:
        args.json.write_text(json.dumps({
            "configurations": points * points * yaws, "ratio_wall": statistics.median(ratios["wall"]),
            "ratio_cpu": statistics.median(ratios["CPU"]), "memory_ratio": peak["command"] / peak["script"],
            "difference": difference}))


if __name__ == "__main__":
    main()
