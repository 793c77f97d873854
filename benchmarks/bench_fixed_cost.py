"""The fixed cost of a command: `screwkit analyze` and the Fig. 5 map as whole processes, and where a command's
time goes before its first configuration.

Usage: python benchmarks/bench_fixed_cost.py [--repeat 7] [--baseline PATH] [--phases]

1. Whole processes, each a new ``python -m screwkit.cli ...`` (wall, CPU and peak resident memory from the
   operating system, ``os.wait4``), with warm caches (numba's kernels and the loaded mechanisms: one unmeasured
   run of each first), run in turn ``--repeat`` times; medians and ranges:

   * ``screwkit analyze planar_5rrr`` (a bundled mechanism at its home pose);
   * the paper's Fig. 5 map, ``screwkit map planar_5rrr --radius 0.6 --step 0.02 --phi-step 1`` (2,821 points x
     360 orientations, 1,015,560 configurations, written as netCDF);
   * the same map on 15 configurations (``--radius 0.02 --step 0.02 --phi-step 120``): its fixed cost;
   * the floor of any command here: ``python -c "import numpy"``, and numba's start-up
     (``import numpy, numba`` and one cached kernel of one line loaded, which sets up numba's compiler context).

   With ``--baseline PATH`` (another checkout of screwkit, e.g. a ``git worktree`` of an older commit), every
   command also runs with ``PYTHONPATH=PATH``, alternating with this checkout's, and the ratio this / baseline is
   taken pair by pair (median, min, max), so that a drift of the machine's speed moves both.
2. With ``--phases``: ``analyze planar_5rrr`` step by step in one process (imports, the mechanism read back
   from the cache or parsed, numba, its compiler context (set up when the first kernel is loaded: it imports
   scipy.linalg, for numba's BLAS check), the index kernels, computing, the report): the process's CPU time
   (steady on a shared machine where wall times are not), medians of ``--repeat`` new processes.
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

HERE = Path(__file__).resolve().parent
CHECKOUT = HERE.parent

FLOOR_KERNEL = '''from numba import njit


@njit(cache=True)
def one(x):
    return x + 1
'''
"""A kernel of one line: loading it from numba's cache sets up numba's compiler context, as the first of
screwkit's kernels does."""

PHASES = r'''
import contextlib, io, json, sys, time
marks = [("start", time.process_time())]
def mark(name):
    marks.append((name, time.process_time()))
import numpy; mark("import numpy")
import click, screwkit.cli, screwkit.cli.analyze as command; mark("import click and the command's modules")
from screwkit.io.loader import load, bundled_path, mechanism_from_description
from screwkit.model.urdf_reader import read_urdf
mechanism = load("planar_5rrr"); mark("load planar_5rrr, read back from the cache")
import pinocchio; mark("import pinocchio (when the file is parsed)")
mechanism_from_description(read_urdf(bundled_path("planar_5rrr"))); mark("parse, build and assemble the file")
import numba; mark("import numba")
import scipy.linalg; mark("import scipy.linalg (numba's check for BLAS, in its context)")
sys.path.insert(0, sys.argv[1]); import floor; floor.one(1); mark("the rest of numba's compiler context")
from screwkit.indices.compiled import driver; mark("the index kernels, loaded from numba's cache")
from screwkit.studies import indices_at_pose
result = indices_at_pose(mechanism, mechanism.home_pose); mark("closure, screws and indices at the pose")
with contextlib.redirect_stdout(io.StringIO()):
    command.print_report(result.to_dict())
mark("the report")
print(json.dumps([(name, 1000 * (t - marks[i][1])) for i, (name, t) in enumerate(marks[1:])]))
'''


def commands(folder: Path) -> dict[str, list[str]]:
    screwkit = [sys.executable, "-m", "screwkit.cli"]
    out = ["--out", str(folder / "map.nc"), "--overwrite", "--quiet"]
    return {
        "analyze planar_5rrr": [*screwkit, "analyze", "planar_5rrr"],
        "Fig. 5 map (1,015,560 configurations)": [*screwkit, "map", "planar_5rrr", "--radius", "0.6", "--step", "0.02",
                                                  "--phi-step", "1", *out],
        "the same map on 15 configurations": [*screwkit, "map", "planar_5rrr", "--radius", "0.02", "--step", "0.02",
                                              "--phi-step", "120", *out],
        # (ended as the command line ends, without the interpreter's teardown: 0.2-0.3 s once numba is loaded)
        "import numpy": [sys.executable, "-c", "import os, numpy; os._exit(0)"],
        "import numpy, numba + a cached kernel": [sys.executable, "-c",
                                                  f"import os, sys; sys.path.insert(0, {str(folder)!r}); import numpy, "
                                                  "numba, floor; floor.one(1); os._exit(0)"],
    }


def measured(arguments: list[str], path: Path) -> tuple[float, float, float]:
    """Wall (s), CPU (s) and peak resident memory (MiB) of one run of a new process, screwkit from ``path`` (run in
    the temporary folder: ``python -m`` and ``-c`` put the working folder first on the import path)."""
    environment = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(path), os.environ.get("PYTHONPATH")])))
    start = time.perf_counter()
    process = subprocess.Popen(arguments, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=environment,
                               cwd=tempfile.gettempdir())
    errors = process.stderr.read().decode()
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - start
    process.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{' '.join(arguments)} failed:\n{errors}")
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024


def spread(values: list[float], digits: int = 2) -> str:
    return f"{statistics.median(values):.{digits}f} ({min(values):.{digits}f}-{max(values):.{digits}f})"


def whole_processes(repeat: int, baseline: Path | None) -> None:
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        (folder / "floor.py").write_text(FLOOR_KERNEL)
        checkouts = {"this": CHECKOUT} | ({"baseline": baseline} if baseline else {})
        runs = {name: {checkout: [] for checkout in checkouts} for name in commands(folder)}
        for arguments in commands(folder).values():
            for path in checkouts.values():  # compiled kernels, mechanisms kept, files in the page cache
                measured(arguments, path)
        for _ in range(repeat):
            for name, arguments in commands(folder).items():
                for checkout, path in checkouts.items():
                    runs[name][checkout].append(measured(arguments, path))
    print(f"whole processes, warm caches, {repeat} runs each in turn: median (min-max)")
    print(f"{'':42s} {'wall s':>20s} {'CPU s':>20s} {'peak MiB':>9s}")
    for name, by_checkout in runs.items():
        for checkout, measures in by_checkout.items():
            wall, cpu, peak = zip(*measures)
            label = name if checkout == "this" else f"  {checkout}"
            print(f"{label:42s} {spread(list(wall)):>20s} {spread(list(cpu)):>20s} {max(peak):9.0f}")
        if baseline:
            ratios = [a[0] / b[0] for a, b in zip(by_checkout["this"], by_checkout["baseline"])]
            cpu_ratios = [a[1] / b[1] for a, b in zip(by_checkout["this"], by_checkout["baseline"])]
            print(f"{'  this / baseline, pair by pair':42s} {spread(ratios, 3):>20s} {spread(cpu_ratios, 3):>20s}")


def phases(repeat: int) -> None:
    with tempfile.TemporaryDirectory() as folder:
        (Path(folder) / "floor.py").write_text(FLOOR_KERNEL)
        environment = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(CHECKOUT),
                                                                                os.environ.get("PYTHONPATH")])))
        run = [sys.executable, "-c", PHASES, folder]
        subprocess.run(run, check=True, capture_output=True, env=environment, cwd=folder)  # cache entry, floor kernel
        measures = [json.loads(subprocess.run(run, check=True, capture_output=True, text=True, env=environment,
                                              cwd=folder).stdout) for _ in range(repeat)]
        start = [measured([sys.executable, "-c", "pass"], CHECKOUT)[1] * 1000 for _ in range(repeat)]
    print(f"analyze planar_5rrr, step by step in one process (CPU ms, median (min-max) of {repeat} processes):")
    print(f"  {'python -c pass (a whole process)':58s} {spread(start, 0):>16s}")
    for index, (name, _) in enumerate(measures[0]):
        print(f"  {name:58s} {spread([measure[index][1] for measure in measures], 0):>16s}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--baseline", type=Path, help="another checkout of screwkit, run alternately with this one")
    parser.add_argument("--phases", action="store_true", help="also analyze planar_5rrr step by step in one process")
    args = parser.parse_args()
    whole_processes(args.repeat, args.baseline)
    if args.phases:
        phases(args.repeat)


if __name__ == "__main__":
    main()
